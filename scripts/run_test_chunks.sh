#!/usr/bin/env bash
# Runs a doctest executable one test suite per process, JOBS processes (default:
# the cores) at a time, so that every core works until the last suite ends.
# The suites known to take longest start first (SLOW_FIRST below: only the
# order depends on it, every suite of the executable runs); a suite that is
# not listed starts after them, in doctest's listing order.
# Each suite's output is printed whole, in listing order, with its own doctest
# summary and its wall seconds in its header; then one line with the totals.
# Exits non-zero if a suite fails or if the suites did not run every test case
# of the executable exactly once.
#   bash scripts/run_test_chunks.sh BUILD/tests/unit_tests [doctest options]
set -euo pipefail
bin=$1
shift
jobs=${JOBS:-$(nproc)}
[[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "run_test_chunks.sh: JOBS must be a positive integer, got '$jobs'" >&2; exit 1; }
# Measured under the sanitizers (about 4x the Release times): these few hold
# half of the run's CPU time (the multi-patch convergence rates, surface
# smoothing on CAD models, the hardening runs, the examples as processes).
SLOW_FIRST=(multipatch_poisson_app meshopt_surface_meshes hardening examples poisson holes_poisson
            poisson_solvers_app app poisson_app meshopt_surface_app)
total=$("$bin" --count | grep -o '[0-9]*$')
mapfile -t suites < <("$bin" --list-test-suites | sed -n '3,$p' | grep -v '^=\|^\[doctest\]' | grep -v '^$')
order=()
for s in "${SLOW_FIRST[@]}"; do
  for t in "${suites[@]}"; do [ "$t" = "$s" ] && order+=("$s"); done
done
for t in "${suites[@]}"; do
  [[ " ${SLOW_FIRST[*]} " == *" $t "* ]] || order+=("$t")
done
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
printf '%s\n' "${order[@]}" |
  xargs -P "$jobs" -I{} bash -c 's=$SECONDS; "$0" --test-suite="{}" "${@:2}" > "$1/{}.log" 2>&1; echo $? > "$1/{}.rc"; echo $((SECONDS - s)) > "$1/{}.sec"' \
    "$bin" "$logs" "$@"
status=0
cases=0
passed=0
failed=0
for s in "${suites[@]}"; do
  echo "== test suite $s ($(cat "$logs/$s.sec" 2>/dev/null || echo '?') s)"
  cat "$logs/$s.log"
  [ "$(cat "$logs/$s.rc" 2>/dev/null)" = 0 ] || status=1
  line=$(grep '^\[doctest\] test cases:' "$logs/$s.log" || true)
  if [ -z "$line" ]; then
    status=1
    continue
  fi
  read -r c p f <<< "$(echo "$line" | grep -o '[0-9]\+' | head -3 | tr '\n' ' ')"
  cases=$((cases + c)) passed=$((passed + p)) failed=$((failed + f))
done
[ "$cases" = "$total" ] || { echo "the suites ran $cases test cases, the executable has $total"; status=1; }
echo "[doctest] all ${#suites[@]} suites, $jobs at a time: test cases: $cases of $total | $passed passed | $failed failed"
exit $status
