#!/usr/bin/env bash
# Runs a doctest executable's test suites in CHUNKS groups (default 8; suites
# dealt round-robin in doctest's listing order), JOBS groups (default: the
# cores) at a time, so that a slow build (the sanitizers') uses every core.
# Each group's output is printed whole, in order, with its own doctest summary;
# then one line with the totals. Exits non-zero if a group fails or if the
# groups did not run every test case of the executable exactly once.
#   bash scripts/run_test_chunks.sh BUILD/tests/unit_tests
set -euo pipefail
bin=$1
chunks=${CHUNKS:-8}
jobs=${JOBS:-$(nproc)}
total=$("$bin" --count | grep -o '[0-9]*$')
mapfile -t suites < <("$bin" --list-test-suites | sed -n '3,$p' | grep -v '^=\|^\[doctest\]' | grep -v '^$')
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
groups=()
for ((k = 0; k < chunks; ++k)); do groups[k]=""; done
for ((i = 0; i < ${#suites[@]}; ++i)); do
  k=$((i % chunks))
  groups[k]="${groups[k]:+${groups[k]},}${suites[i]}"
done
for ((k = 0; k < chunks; ++k)); do
  [ -n "${groups[k]}" ] && printf '%s %s\n' "$k" "${groups[k]}"
done |
  xargs -P "$jobs" -L 1 bash -c '"$0" --test-suite="$3" > "$1/$2.log" 2>&1; echo $? > "$1/$2.rc"' "$bin" "$logs"
status=0
cases=0
passed=0
failed=0
for ((k = 0; k < chunks; ++k)); do
  [ -n "${groups[k]}" ] || continue
  echo "== test suites ${groups[k]}"
  cat "$logs/$k.log"
  [ "$(cat "$logs/$k.rc" 2>/dev/null)" = 0 ] || status=1
  line=$(grep '^\[doctest\] test cases:' "$logs/$k.log" || true)
  if [ -z "$line" ]; then
    status=1
    continue
  fi
  read -r c p f <<< "$(echo "$line" | grep -o '[0-9]\+' | head -3 | tr '\n' ' ')"
  cases=$((cases + c)) passed=$((passed + p)) failed=$((failed + f))
done
[ "$cases" = "$total" ] || { echo "the groups ran $cases test cases, the executable has $total"; status=1; }
echo "[doctest] all ${#suites[@]} suites in $chunks groups: test cases: $cases of $total | $passed passed | $failed failed"
exit $status
