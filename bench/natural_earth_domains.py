#!/usr/bin/env python3
"""Domains for `tspline param` from Natural Earth GeoJSON (countries or land polygons).

Writes the text format of tests/data (`x y` per line in km, rings separated by a
blank line, the first ring the outer boundary), projected equirectangularly about
the domain's centre (x = R cos(lat0) (lon - lon0), y = R (lat - lat0), R = 6371 km),
as tests/data/coastlines/SOURCE.md describes; repeated points removed, nothing else
cleaned.

  island  GEOJSON K OUT             the K-th largest polygon (0: the largest), its outer ring
  sea     GEOJSON OUT [W S E N]     a box of sea (the islands' bounding box grown by 10 %,
                                    or the given lon/lat box) with every polygon wholly
                                    inside it as a hole

Polygons that cross the antimeridian are not handled.
"""
import json
import math
import sys

from make_variants import write_rings  # (the same directory: the text format of tests/data)

EARTH_RADIUS_KM = 6371.0
MM = 6  # decimals of a km written: a millimetre, below the data's own precision


def outer_rings(path):
    """The outer ring of every polygon of every feature, in lon/lat."""
    data = json.load(open(path))
    features = data["features"] if "features" in data else [data]
    rings = []
    for f in features:
        g = f["geometry"] if "geometry" in f else f
        polygons = g["coordinates"] if g["type"] == "MultiPolygon" else [g["coordinates"]]
        rings.extend(p[0] for p in polygons)
    return rings


def lonlat_area(ring):
    return 0.5 * abs(sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:] + ring[:1])))


def project(rings, lon0, lat0):
    c = math.cos(math.radians(lat0))
    out = []
    for ring in rings:
        pts = [(EARTH_RADIUS_KM * c * math.radians(x - lon0), EARTH_RADIUS_KM * math.radians(y - lat0))
               for x, y, *_ in ring]
        kept = []
        for p in pts:
            if not kept or p != kept[-1]:
                kept.append(p)
        while len(kept) > 1 and kept[0] == kept[-1]:
            kept.pop()
        out.append(kept)
    return out


def island(src, k, out):
    rings = sorted(outer_rings(src), key=lonlat_area, reverse=True)
    ring = rings[k]
    lon0 = sum(p[0] for p in ring) / len(ring)
    lat0 = sum(p[1] for p in ring) / len(ring)
    write_rings(out, project([ring], lon0, lat0),
                f"polygon {k} (by area) of {src}, km about ({lon0:.4f}, {lat0:.4f})", MM)


def sea(src, out, box=None):
    rings = outer_rings(src)
    if box:
        w, s, e, n = box
        rings = [r for r in rings if all(w < x < e and s < y < n for x, y, *_ in r)]
    else:
        xs = [p[0] for r in rings for p in r]
        ys = [p[1] for r in rings for p in r]
        gx, gy = 0.1 * (max(xs) - min(xs)), 0.1 * (max(ys) - min(ys))
        w, s, e, n = min(xs) - gx, min(ys) - gy, max(xs) + gx, max(ys) + gy
    rings.sort(key=lonlat_area, reverse=True)
    lon0, lat0 = 0.5 * (w + e), 0.5 * (s + n)
    box_ring = [(w, s), (e, s), (e, n), (w, n)]
    write_rings(out, project([box_ring] + rings, lon0, lat0),
                f"sea box ({w}, {s}, {e}, {n}) of {src} with {len(rings)} islands as holes, km", MM)


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "island":
        island(sys.argv[2], int(sys.argv[3]), sys.argv[4])
    elif len(sys.argv) in (4, 8) and sys.argv[1] == "sea":
        sea(sys.argv[2], sys.argv[3], [float(v) for v in sys.argv[4:8]] if len(sys.argv) == 8 else None)
    else:
        sys.exit(__doc__)
