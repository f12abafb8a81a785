# Sourced by scripts/sanitize.sh and scripts/fuzz.sh: configures the one reliability tree they share (clang,
# AddressSanitizer + UndefinedBehaviorSanitizer, libFuzzer coverage; docs/reliability.md) in ./build-asan
# (override with DYNID_ASAN_DIR). Line tables only: the sanitizers' reports need file and line, and full -g made
# the tree 6.2 GB (a CI machine ran out of disk). The unit tests and the fuzz targets link the same instrumented
# libraries, so the libraries are compiled once. Expects $here (the source folder); sets $build and $jobs.
build=${DYNID_ASAN_DIR:-$here/build-asan}
jobs=${DYNID_JOBS:-2}
cmake -S "$here" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -gline-tables-only" \
  -DDYNID_SANITIZE=ON -DDYNID_FUZZ=ON -DBUILD_TESTING=ON -DDYNID_BUILD_BENCHMARKS=OFF >/dev/null
