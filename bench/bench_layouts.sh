#!/usr/bin/env bash
# Layouts end to end: `tspline param` (default options unless EXTRA is set) on
# every domain given (default: all of ../shared/data's seas, holes, coastlines
# and polygons), one line per domain: layout, patches, cells, Bezier elements,
# certified, certified det J bound (relative), whole-map J_r and scaled Jacobian
# (dense sample), area error, largest interface gap / diameter, wall seconds,
# peak MiB (/usr/bin/time). Release build: `bash scripts/build.sh` first, or
# NO_BUILD=1 to use build/ as it is. Usage: bash bench/bench_layouts.sh [FILES...]
set -uo pipefail
cd "$(dirname "$0")/.."
[ "${NO_BUILD:-0}" = 1 ] || BUILD_DIR=build bash scripts/build.sh > /dev/null
SHARED=${SHARED:-../shared/data}
if [ $# -eq 0 ]; then set -- "$SHARED"/seas/*.txt "$SHARED"/holes/*.txt "$SHARED"/coastlines/*.txt "$SHARED"/polygons/*.txt; fi
OUT=$(mktemp -d)
for f in "$@"; do
  n=$(basename "${f%.*}")
  s=$(date +%s.%N)
  /usr/bin/time -f "%M" -o "$OUT/$n.mem" build/apps/tspline param "$f" --out "$OUT/$n" -q ${EXTRA:-} 2> "$OUT/$n.err"
  rc=$?
  t=$(echo "$(date +%s.%N) - $s" | bc)
  python3 - "$OUT/$n/report.json" "$n" "$rc" "$t" "$(tail -1 "$OUT/$n.mem")" "$OUT/$n.err" <<'PY'
import json, sys
path, name, rc, t, mem, err = sys.argv[1:]
try:
    r = json.load(open(path))
except Exception:
    print(f"{name}: exit {rc}, no report: {open(err).read().strip()[:300]}")
    sys.exit()
mib = int(mem) // 1024 if mem.isdigit() else -1
def g(v):  # a figure, or ? where the report has none (null: not finite)
    return f"{v:.3g}" if isinstance(v, (int, float)) else "?"
layout = r.get("layout", {}).get("chosen", "?")
if "totals" in r:
    T = r["totals"]
    W = T.get("whole_map", {})
    print(f"{name}: exit {rc}, layout {layout}, {len(r['patches'])} patches, {T['cells']} cells, "
          f"{T['bezier_elements']} elements, certified {T['certified_valid']}, det J bound {g(T['min_relative_det_lower_bound'])}, "
          f"J_r {g(T['min_mean_ratio_whole_map'])}, SJ {g(T['min_scaled_jacobian_whole_map'])} (dense 9x9), "
          f"certified J_r >= {g(W.get('mean_ratio', {}).get('certified_lower_bound'))}, SJ >= {g(W.get('scaled_jacobian', {}).get('certified_lower_bound'))}, "
          f"area error {g(T['area_relative_error'])}, gap {g(T['max_interface_gap_relative'])}, {float(t):.1f} s, {mib} MiB")
else:
    w = r["jacobian"]["whole_map"]
    c = r["certification"]
    print(f"{name}: exit {rc}, layout {layout}, 1 patch, {r['counts']['cells']} cells, {c['elements']} elements, "
          f"certified {r['certified_valid']}, det J bound {g(c['min_relative_det_lower_bound'])}, "
          f"J_r {g(w['min_mean_ratio'])}, SJ {g(w['min_scaled'])} (dense 9x9), "
          f"certified J_r >= {g(w.get('mean_ratio', {}).get('certified_lower_bound'))}, SJ >= {g(w.get('scaled_jacobian', {}).get('certified_lower_bound'))}, "
          f"{float(t):.1f} s, {mib} MiB")
PY
done
rm -rf "$OUT"
