#!/usr/bin/env bash
# All tests: installs what is missing, builds, runs the doctest suites in a
# Release build, then again in an optimized build with debug info under AddressSanitizer and
# UndefinedBehaviorSanitizer (-O1 -g1). Between the two, installs the Release build into
# build/install and builds and runs tests/downstream against the installed
# CMake package (and imports the installed Python module). The Python tests
# (pytest, tests/python) run after the Release suites, not under the sanitizers,
# and then every command of README.md (scripts/run_readme_commands.sh).
# Before the sanitizer suites, the libFuzzer targets (scripts/run_fuzz.sh: clang,
# ASan, 20 s each, one per core at a time), so that the run still ends with
# doctest's summaries. Both doctest runs go in groups of suites, one per core at
# a time (scripts/run_test_chunks.sh), with a total at the end.
# Exits non-zero if any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
# Each stage's header says when it starts (minutes since the start), so that a
# log shows where the time goes.
START=$SECONDS
stage() { printf '== %s (at %d min %02d s)\n' "$1" $(((SECONDS - START) / 60)) $(((SECONDS - START) % 60)); }
stage "Release build and tests"
# The Python module is built for, and tested with, Debian's interpreter (where
# install_deps put numpy and pytest), whatever python3 comes first on PATH.
PYTHON=${PYTHON:-/usr/bin/python3}
BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh -DPython3_EXECUTABLE="$PYTHON"
# Most test cases run on one core: the suites in groups, one per core at a time
# (scripts/run_test_chunks.sh), each group with its doctest summary.
bash scripts/run_test_chunks.sh ./build/tests/unit_tests
stage "Python module (pytest; build/python)"
PYTHONPATH="$PWD/build/python" "$PYTHON" -m pytest -p no:cacheprovider tests/python
stage "README commands (every command of README.md, against the Release build)"
BUILD_DIR=build PYTHON="$PYTHON" bash scripts/run_readme_commands.sh
stage "Installed package: cmake --install, then a downstream project with find_package(TSpline)"
rm -rf build/install build/downstream
cmake --install build --prefix "$PWD/build/install" > build/install.log
cmake -S tests/downstream -B build/downstream -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PWD/build/install" \
  > build/downstream.configure.log 2>&1 || { cat build/downstream.configure.log; exit 1; }
cmake --build build/downstream -j "$(nproc)"
./build/downstream/downstream_check
PYTHONPATH="$PWD/build/install/lib/python3/dist-packages" "$PYTHON" -c \
  "import tspline, numpy as np; m = tspline.parameterize(np.loadtxt('tests/data/polygons/square.txt'), init_level=2, max_adapt=1); assert m.certified_valid; print('installed Python module: ok')"
stage "Fuzz targets (libFuzzer, ASan+UBSan; bounded time each)"
bash scripts/run_fuzz.sh
stage "ASan+UBSan build and tests"
# -O1 -g1 (line tables for the sanitizer's stack traces): about half the compile
# time of RelWithDebInfo's -O2 -g, as the sanitizers' documentation recommends.
BUILD_DIR=build-asan BUILD_TYPE=RelWithDebInfo bash scripts/build.sh -DTSPLINE_SANITIZE=ON -DTSPLINE_BUILD_BENCH=OFF \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
# The sanitized suites run about four times slower than the Release ones: in
# groups of suites, one per core at a time (scripts/run_test_chunks.sh), each
# group with its doctest summary and a total at the end.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  bash scripts/run_test_chunks.sh ./build-asan/tests/unit_tests
stage "done"
