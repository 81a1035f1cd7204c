#!/usr/bin/env python3
"""Copies of polygon files as held-out input would differ from them: rotated
by 37 degrees about the outer ring's centroid, mirrored (x -> -x), rescaled
to metres far from the origin (x 1000, shifted by (3.2e5, -4.1e6)), and with
every ring reversed. The mesher, and so a quad layout, is not invariant under
these; the maps should stay certified and good.

Usage: python3 bench/make_variants.py OUTDIR FILE...
then:  NO_BUILD=1 bash bench/bench_layouts.sh OUTDIR/*.txt
"""
import math
import os
import sys


def read_rings(path):
    rings = [[]]
    for line in open(path):
        line = line.strip()
        if line.startswith("#"):
            continue
        if not line:
            if rings[-1]:
                rings.append([])
            continue
        x, y = map(float, line.split()[:2])
        rings[-1].append((x, y))
    return [r for r in rings if r]


def write_rings(path, rings, what, decimals=None):
    """The rings in the text format of tests/data; every digit of a double, or `decimals` after the point."""
    with open(path, "w") as f:
        f.write(f"# {what}\n")
        for i, ring in enumerate(rings):
            if i:
                f.write("\n")
            for x, y in ring:
                f.write(f"{x:.17g} {y:.17g}\n" if decimals is None else f"{x:.{decimals}f} {y:.{decimals}f}\n")


def variants(rings):
    outer = rings[0]
    cx = sum(x for x, _ in outer) / len(outer)
    cy = sum(y for _, y in outer) / len(outer)
    c, s = math.cos(math.radians(37)), math.sin(math.radians(37))
    return {
        "rot37": [[(cx + (x - cx) * c - (y - cy) * s, cy + (x - cx) * s + (y - cy) * c) for x, y in r] for r in rings],
        "mirror": [[(-x, y) for x, y in r] for r in rings],
        "metres": [[(1000 * x + 3.2e5, 1000 * y - 4.1e6) for x, y in r] for r in rings],
        "reversed": [list(reversed(r)) for r in rings],
    }


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    for path in sys.argv[2:]:
        name = os.path.splitext(os.path.basename(path))[0]
        for kind, rings in variants(read_rings(path)).items():
            write_rings(os.path.join(out, f"{name}_{kind}.txt"), rings, f"{name}, {kind} (bench/make_variants.py)")


if __name__ == "__main__":
    main()
