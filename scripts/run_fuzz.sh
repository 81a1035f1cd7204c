#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz: clang, ASan + UBSan, -O1, only the
# sources they need) into BUILD_DIR (default build-fuzz) and runs each for
# FUZZ_SECONDS (default 20) on a copy of its seed corpus tests/fuzz/corpus/TARGET
# (the copy grows; the corpus in the repository stays as it is). Prints the
# executions of each run; exits non-zero if a target finds a crash, a leak, a
# timeout (one input over 10 s) or an unexpected exception (the reproducer is
# left in BUILD_DIR/findings/TARGET).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-20}
JOBS=${JOBS:-$(nproc)}
CXX=clang++ cmake -S tests/fuzz -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=None > "$BUILD_DIR.configure.log" 2>&1 \
  || { cat "$BUILD_DIR.configure.log"; exit 1; }
cmake --build "$BUILD_DIR" -j "$JOBS"
status=0
for t in polygon_text geojson gis tspline_file front; do
  corpus_src=tests/fuzz/corpus/$t
  corpus=$BUILD_DIR/corpus/$t
  findings=$BUILD_DIR/findings/$t
  rm -rf "$corpus" "$findings"
  mkdir -p "$corpus" "$findings"
  cp "$corpus_src"/* "$corpus"/
  log=$BUILD_DIR/fuzz_$t.log
  # -timeout: an input that runs longer is a hang; -rss_limit_mb: memory blow-up.
  if ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     "$BUILD_DIR/fuzz_$t" -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
       -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" > "$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_$t: $runs executions in ${FUZZ_SECONDS} s, nothing found"
  else
    echo "fuzz_$t: FAILED (see $log; reproducer in $findings)"
    tail -40 "$log"
    status=1
  fi
done
exit $status
