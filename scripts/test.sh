#!/usr/bin/env bash
# The project's test command: setup + configure + build + every test (README.md).
#
#   scripts/test.sh              build in ./build and run all tests
#   BUILD_DIR=dir JOBS=n scripts/test.sh
#   CXX=g++ scripts/test.sh      build with another compiler (default: clang++, which builds
#                                the Eigen-heavy modules in about half of g++'s time)
#   CI=true makes compiler warnings errors and a test whose facility is missing (root and
#   network namespaces, numpy, matplotlib, java) fail instead of being skipped.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}
WERROR=OFF
[ "${CI:-}" = "true" ] && WERROR=ON

scripts/setup.sh

# The compiler is chosen when the build directory is first configured (CMake keeps it).
compiler=()
if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
  cxx=${CXX:-clang++}
  cc=${CC:-$([ "$cxx" = clang++ ] && echo clang || echo cc)}
  compiler=(-DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx")
fi

start=$(date +%s)
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCVSLAM_WERROR=$WERROR "${compiler[@]}"
cmake --build "$BUILD_DIR" -j "$JOBS"
echo "test.sh: build took $(( $(date +%s) - start )) s"

# ctest starts the longest tests first when it knows their costs (Testing/Temporary/
# CTestCostData.txt, rewritten by every run). A fresh build directory starts from the costs of
# a full run on the 2-core CI machine (tests/ctest_costs.txt), so that the longest tests do not
# start last; names it does not know are ignored, new tests cost 0 until measured.
costs="$BUILD_DIR/Testing/Temporary/CTestCostData.txt"
if [ ! -f "$costs" ]; then
  mkdir -p "$(dirname "$costs")"
  cp tests/ctest_costs.txt "$costs"
fi

start=$(date +%s)
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" --timeout 900
echo "test.sh: tests took $(( $(date +%s) - start )) s"
