#!/usr/bin/env bash
# SwarmBox test suite: set up the machine, build everything, run every test under ctest.
# This is the README's test command, and all that .ci/run calls.
#   bash scripts/test.sh                 # the whole suite (unit, integration, Docker end-to-end)
#   bash scripts/test.sh -L unit         # extra arguments go to ctest
# Environment: BUILD_DIR (default build), JOBS (default: number of cores).
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/setup.sh

BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-$(nproc)}
werror=OFF
[ "${CI:-}" = "true" ] && werror=ON   # warnings are errors in CI

cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSWARMBOX_WERROR="$werror" >/dev/null
cmake --build "$BUILD_DIR" -j "$JOBS"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" "$@"
