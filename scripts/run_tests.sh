#!/usr/bin/env bash
# All tests: installs what is missing, builds, runs the doctest suites in a
# Release build, then again in an optimized build with debug info under AddressSanitizer and
# UndefinedBehaviorSanitizer. Exits non-zero if any test fails.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
echo "== Release build and tests"
BUILD_DIR=build BUILD_TYPE=Release bash scripts/build.sh
./build/tests/unit_tests
echo "== ASan+UBSan build and tests"
BUILD_DIR=build-asan BUILD_TYPE=RelWithDebInfo bash scripts/build.sh -DTSPLINE_SANITIZE=ON -DTSPLINE_BUILD_BENCH=OFF
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ./build-asan/tests/unit_tests
