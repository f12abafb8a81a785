#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of dynid and its unit tests in ./build-asan
# (override with DYNID_ASAN_DIR), then runs the tests. Only the test executables are built (no CLI, no benchmarks).
#   scripts/sanitize.sh [label-regex]    ctest labels to run (default: unit)
# Two long numerical tests are left out (about 3 of the suite's 4.5 CPU minutes under the sanitizers; they run in
# the normal suite); DYNID_SANITIZE_EXCLUDE="" runs them too.
# Findings stop the test (halt_on_error); third-party suppressions: scripts/sanitizer/ (each with its reason).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=${DYNID_ASAN_DIR:-$here/build-asan}
labels=${1:-unit}
exclude=${DYNID_SANITIZE_EXCLUDE-NoiseStudy.DynidLocatesWithinTopThree|Sensitivity.SparseTruncatedExpansionWithStaticCorrection}
jobs=${DYNID_JOBS:-2}

start=$(date +%s)
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g" -DDYNID_SANITIZE=ON \
  -DDYNID_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target unit_tests
built=$(date +%s)
# shellcheck source=sanitizer/options.sh
source "$here/scripts/sanitizer/options.sh"
ctest --test-dir "$build" -L "$labels" ${exclude:+-E "$exclude"} --output-on-failure -j "$jobs"
end=$(date +%s)
echo "dynid sanitize: build $((built - start)) s, tests (-L $labels) $((end - built)) s"
