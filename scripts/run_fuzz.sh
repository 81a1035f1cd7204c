#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz: clang, ASan + UBSan, -O1, only the
# sources they need) into BUILD_DIR (default build-fuzz) and runs each for
# FUZZ_SECONDS (default 20), JOBS (default: the cores) at a time, on a copy of
# its seed corpus tests/fuzz/corpus/TARGET (the copy grows; the corpus in the
# repository stays as it is). Prints the
# executions of each run; exits non-zero if a target finds a crash, a leak, a
# timeout (one input over 10 s) or an unexpected exception (the reproducer is
# left in BUILD_DIR/findings/TARGET).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-20}
JOBS=${JOBS:-$(nproc)}
# libFuzzer reads a bad -max_total_time as 0, which means "run forever".
[[ $FUZZ_SECONDS =~ ^[1-9][0-9]*$ ]] || { echo "run_fuzz.sh: FUZZ_SECONDS must be a positive integer, got '$FUZZ_SECONDS'" >&2; exit 1; }
[[ $JOBS =~ ^[1-9][0-9]*$ ]] || { echo "run_fuzz.sh: JOBS must be a positive integer, got '$JOBS'" >&2; exit 1; }
CXX=clang++ cmake -S tests/fuzz -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=None > "$BUILD_DIR.configure.log" 2>&1 \
  || { cat "$BUILD_DIR.configure.log"; exit 1; }
cmake --build "$BUILD_DIR" -j "$JOBS"
# One target's run; prints its result line (and the log's tail if it failed).
fuzz_one() {
  local t=$1
  local corpus=$BUILD_DIR/corpus/$t findings=$BUILD_DIR/findings/$t log=$BUILD_DIR/fuzz_$t.log
  rm -rf "$corpus" "$findings"
  mkdir -p "$corpus" "$findings"
  cp tests/fuzz/corpus/"$t"/* "$corpus"/
  # -timeout: an input that runs longer is a hang; -rss_limit_mb: memory blow-up.
  if ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
     "$BUILD_DIR/fuzz_$t" -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
       -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" > "$log" 2>&1; then
    local runs
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_$t: $runs executions in ${FUZZ_SECONDS} s, nothing found"
  else
    echo "fuzz_$t: FAILED (see $log; reproducer in $findings)"
    tail -40 "$log"
    return 1
  fi
}
export -f fuzz_one
export BUILD_DIR FUZZ_SECONDS
# Each fuzzer is one process on one core: JOBS of them at a time (each still
# gets its FUZZ_SECONDS), their result lines in the listed order at the end.
results=$(mktemp -d)
trap 'rm -rf "$results"' EXIT
printf '%s\n' polygon_text geojson gis tspline_file front |
  xargs -P "$JOBS" -I{} bash -c 'fuzz_one {} > "$0/{}.out" 2>&1; echo $? > "$0/{}.rc"' "$results"
status=0
for t in polygon_text geojson gis tspline_file front; do
  cat "$results/$t.out"
  [ "$(cat "$results/$t.rc" 2>/dev/null)" = 0 ] || status=1
done
exit $status
