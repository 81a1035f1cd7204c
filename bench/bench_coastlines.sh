#!/usr/bin/env bash
# `tspline param` with default options on every bundled coastline and test
# polygon (Release build): one row per domain with what the final map is
# (from report.json), the wall time and the peak memory of the run.
# Usage: bash bench/bench_coastlines.sh [DOMAIN ...]   (default: tests/data/coastlines/*.txt tests/data/polygons/*.txt)
# OPTIMIZER=lbfgs|newton passes --optimizer to tspline param (default: its default);
# NO_BUILD=1 skips the build.
set -euo pipefail
cd "$(dirname "$0")/.."
[ "${NO_BUILD:-0}" = 1 ] || BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh > /dev/null
extra=()
[ -z "${OPTIMIZER:-}" ] || extra=(--optimizer "$OPTIMIZER")
domains=("$@")
[ ${#domains[@]} -gt 0 ] || domains=(tests/data/coastlines/*.txt tests/data/polygons/*.txt)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf "%-18s %8s %7s %8s %5s %10s %9s %9s %8s %8s %4s\n" domain vertices cells elements cert det_bound Jr_whole Jr_gauss seconds peak_MiB exit
for f in "${domains[@]}"; do
  n=$(basename "$f" .txt)
  set +e
  /usr/bin/time -f "%e %M" -o "$tmp/time" build/apps/tspline param "$f" --out "$tmp/$n" --quiet "${extra[@]}" > /dev/null 2> "$tmp/err"
  rc=$?
  set -e
  read -r secs kb < <(tail -n 1 "$tmp/time")
  if [ -f "$tmp/$n/report.json" ]; then
    python3 - "$tmp/$n/report.json" "$n" "$secs" "$kb" "$rc" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); n, secs, kb, rc = sys.argv[2:6]
c = r.get("certification", {})
print("%-18s %8d %7d %8d %5s %10.3g %9.4f %9.4f %8.2f %8.0f %4s" % (
    n, r["counts"]["polygon_vertices"], r["counts"]["cells"], c.get("elements", 0),
    "yes" if r.get("certified_valid") else "no", c.get("min_relative_det_lower_bound") or float("nan"),
    r["jacobian"]["whole_map"]["min_mean_ratio"], r["jacobian"]["min_mean_ratio_jacobian"],
    float(secs), int(kb) / 1024.0, rc))
PY
  else
    printf "%-18s %8s %7s %8s %5s %10s %9s %9s %8.2f %8.0f %4s  %s\n" "$n" - - - - - - - "$secs" "$((kb / 1024))" "$rc" "$(head -c 120 "$tmp/err")"
  fi
done
