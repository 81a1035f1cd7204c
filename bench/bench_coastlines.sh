#!/usr/bin/env bash
# `tspline param` with default options on every bundled coastline and test
# polygon (Release build): one row per domain with what the final map is
# (from report.json), the wall time and the peak memory of the run.
# Usage: bash bench/bench_coastlines.sh [DOMAIN ...]   (default: tests/data/coastlines/*.txt tests/data/polygons/*.txt)
# OPTIMIZER=lbfgs|newton passes --optimizer to tspline param (default: its default);
# LAYOUT=single|quad|auto passes --layout (default: its default, auto);
# TSPLINE=path runs that binary instead of build/apps/tspline (e.g. an older build, for before/after);
# NO_BUILD=1 skips the build. cpu_s is the process's user + system time (all threads).
set -euo pipefail
cd "$(dirname "$0")/.."
[ "${NO_BUILD:-0}" = 1 ] || BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh > /dev/null
extra=()
[ -z "${OPTIMIZER:-}" ] || extra+=(--optimizer "$OPTIMIZER")
[ -z "${LAYOUT:-}" ] || extra+=(--layout "$LAYOUT")
bin=${TSPLINE:-build/apps/tspline}
domains=("$@")
[ ${#domains[@]} -gt 0 ] || domains=(tests/data/coastlines/*.txt tests/data/polygons/*.txt)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# Jr_cert / SJ_cert: certified lower bounds of J_r and of the scaled Jacobian
# over the whole map; Jr_26 / SJ_26: minima of the 26 x 26 sample per element;
# Jr_gauss: minimum at the Gauss points (report.json jacobian.whole_map, or totals
# for a quad layout: layout quad/P = P patches).
printf "%-18s %-9s %8s %7s %8s %5s %10s %8s %8s %8s %8s %9s %8s %8s %8s %4s\n" domain layout vertices cells elements cert det_bound Jr_cert Jr_26 SJ_cert SJ_26 Jr_gauss seconds cpu_s peak_MiB exit
for f in "${domains[@]}"; do
  n=$(basename "$f" .txt)
  set +e
  /usr/bin/time -f "%e %M %U %S" -o "$tmp/time" "$bin" param "$f" --out "$tmp/$n" --quiet "${extra[@]}" > /dev/null 2> "$tmp/err"
  rc=$?
  set -e
  read -r secs kb usr sys < <(tail -n 1 "$tmp/time")
  cpu=$(python3 -c "print('%.2f' % ($usr + $sys))")
  if [ -f "$tmp/$n/report.json" ]; then
    python3 - "$tmp/$n/report.json" "$n" "$secs" "$kb" "$rc" "$cpu" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); n, secs, kb, rc, cpu = sys.argv[2:7]
if "totals" in r:  # a quad layout: one map per patch, the whole map's figures in totals
    T = r["totals"]
    w = T["whole_map"]
    cells, elements, cert, bound, gauss = T["cells"], T["bezier_elements"], T["certified_valid"], T["min_relative_det_lower_bound"], T["min_mean_ratio_gauss"]
    vertices = sum(1 for line in open(r["input"]) if line.strip() and not line.lstrip().startswith("#"))
    layout = "quad/%d" % r["patches_count"]
else:
    c = r.get("certification", {})
    w = r["jacobian"]["whole_map"]
    cells, elements, cert, bound, gauss = r["counts"]["cells"], c.get("elements", 0), r.get("certified_valid"), c.get("min_relative_det_lower_bound"), r["jacobian"]["min_mean_ratio_jacobian"]
    vertices = r["counts"]["polygon_vertices"]
    layout = "single"
jr, sj = w["mean_ratio"], w["scaled_jacobian"]
print("%-18s %-9s %8d %7d %8d %5s %10.3g %8.4f %8.4f %8.4f %8.4f %9.4f %8.2f %8s %8.0f %4s" % (
    n, layout, vertices, cells, elements,
    "yes" if cert else "no", bound if bound is not None else float("nan"),
    jr["certified_lower_bound"], jr["sampled_min"], sj["certified_lower_bound"], sj["sampled_min"],
    gauss, float(secs), cpu, int(kb) / 1024.0, rc))
PY
  else
    printf "%-18s %-9s %8s %7s %8s %5s %10s %8s %8s %8s %8s %9s %8.2f %8s %8.0f %4s  %s\n" "$n" - - - - - - - - - - - "$secs" "$cpu" "$((kb / 1024))" "$rc" "$(head -c 120 "$tmp/err")"
  fi
done
