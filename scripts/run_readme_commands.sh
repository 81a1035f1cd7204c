#!/usr/bin/env bash
# Runs every command of README.md, so that the README cannot go stale: every
# line of every ```sh block (except comment lines and the two top-level
# commands `bash scripts/run_example.sh` and `bash scripts/run_tests.sh`, which
# CI runs itself), in order, each in its own `bash` with `set -euo pipefail`;
# then every ```python block with the Python module of the build.
# They run in a scratch directory, out/readme-check, in which tests/,
# examples/, python/, scripts/ and docs/ link to the repository's and build/ to
# BUILD_DIR, so that the README's paths resolve and its outputs (out/...) land
# in out/readme-check/out/. `python3` in the commands is PYTHON (the
# interpreter the module is built for). The scratch directory is removed at
# the end. Exits non-zero, naming the command and showing the end of its
# output, at the first command that fails.
#   bash scripts/run_readme_commands.sh
# BUILD_DIR (default build): a Release build of the project (scripts/build.sh);
# PYTHON (default /usr/bin/python3); VERBOSE=1 prints every command's output;
# KEEP=1 keeps out/readme-check.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
readme=$root/README.md
build_dir=${BUILD_DIR:-build}
python=${PYTHON:-/usr/bin/python3}
scratch=$root/out/readme-check

if [ ! -x "$build_dir/apps/tspline" ]; then
  echo "run_readme_commands: no $build_dir/apps/tspline: build first (bash scripts/build.sh) or set BUILD_DIR" >&2
  exit 1
fi
build_abs=$(cd "$build_dir" && pwd)

# The commands: the lines of the ```sh blocks, a line ending in a backslash
# joined with the next.
mapfile -t commands < <(awk '
  /^```sh[[:space:]]*$/ { in_block = 1; next }
  /^```/ { in_block = 0; next }
  in_block {
    line = pending $0; pending = ""
    if (line ~ /\\$/) { pending = substr(line, 1, length(line) - 1); next }
    sub(/^[[:space:]]+/, "", line); sub(/[[:space:]]+$/, "", line)
    if (line == "" || line ~ /^#/) next
    if (line == "bash scripts/run_example.sh" || line == "bash scripts/run_tests.sh") next
    print line
  }' "$readme")
# The ```python blocks, each one script.
python_blocks=$(awk '/^```python[[:space:]]*$/ { n++ } END { print n + 0 }' "$readme")
for c in "${commands[@]}"; do
  case $c in
    *run_tests.sh* | *run_example.sh* | *run_readme_commands.sh* | *install_deps.sh* | *build.sh*)
      echo "run_readme_commands: refusing a README command that builds, installs or runs the tests: $c" >&2
      echo "  (only the exact lines 'bash scripts/run_example.sh' and 'bash scripts/run_tests.sh' are skipped)" >&2
      exit 1 ;;
  esac
done
if [ ${#commands[@]} -eq 0 ]; then
  echo "run_readme_commands: found no command in the sh blocks of $readme" >&2
  exit 1
fi

cleanup() { if [ "${KEEP:-0}" != 1 ]; then rm -rf "$scratch"; fi; }
trap cleanup EXIT
rm -rf "$scratch"
mkdir -p "$scratch/bin"
for d in tests examples python scripts docs; do ln -s "$root/$d" "$scratch/$d"; done
ln -s "$build_abs" "$scratch/build"
ln -s "$python" "$scratch/bin/python3"
export PATH="$scratch/bin:$PATH"

total=$((${#commands[@]} + python_blocks))
log=$scratch/command.log
n=0
start_all=$SECONDS

run() {  # run DESCRIPTION COMMAND...: runs COMMAND in the scratch directory
  local what=$1
  shift
  n=$((n + 1))
  echo "[$n/$total] $what"
  local start=$SECONDS status=0
  (cd "$scratch" && "$@") > "$log" 2>&1 || status=$?
  if [ "${VERBOSE:-0}" = 1 ]; then sed 's/^/    /' "$log"; fi
  if [ $status -ne 0 ]; then
    echo "run_readme_commands: README command failed with exit status $status:" >&2
    echo "  $what" >&2
    echo "its output (last 40 lines):" >&2
    tail -n 40 "$log" | sed 's/^/    /' >&2
    exit 1
  fi
  echo "    ok ($((SECONDS - start)) s)"
}

for c in "${commands[@]}"; do
  run "\$ $c" bash -c "set -euo pipefail; $c"
done
for ((k = 1; k <= python_blocks; ++k)); do
  awk -v want="$k" '/^```python[[:space:]]*$/ { n++; in_block = (n == want); next }
                    /^```/ { in_block = 0; next }
                    in_block' "$readme" > "$scratch/readme_python_$k.py"
  run "python block $k of README.md (PYTHONPATH=build/python python3)" \
    env PYTHONPATH="$scratch/build/python" "$python" "readme_python_$k.py"
done
echo "== README commands: all $total ran in $((SECONDS - start_all)) s"
