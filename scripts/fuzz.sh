#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, clang, ASan + UBSan) in ./build-asan (the tree scripts/sanitize.sh shares:
# scripts/sanitizer/configure.sh) and runs each on its seed corpus fuzz/corpus/<target>/ (read only; new inputs
# go to build-asan/corpus/<target>/).
#   scripts/fuzz.sh [seconds] [runs] [target...]   per target: stop after `seconds` (default 60) or `runs`
#                                                    executions (-1: no limit); default: every fuzz/fuzz_*.cpp
# Prints the executions per target; exits non-zero on any finding (crash input in build-asan/artifacts/).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-60}
runs=${2:--1}
shift $(($# < 2 ? $# : 2))
targets=("$@")
if ((${#targets[@]} == 0)); then
  for src in "$here"/fuzz/fuzz_*.cpp; do targets+=("$(basename "$src" .cpp)"); done
fi

# shellcheck source=sanitizer/configure.sh
source "$here/scripts/sanitizer/configure.sh"
cmake --build "$build" -j "$jobs" --target fuzz_targets
# shellcheck source=sanitizer/options.sh
source "$here/scripts/sanitizer/options.sh"

status=0
summary=""
mkdir -p "$build/artifacts"
for t in "${targets[@]}"; do
  mkdir -p "$build/corpus/$t"
  dict=()
  [ -f "$here/fuzz/$t.dict" ] && dict=("-dict=$here/fuzz/$t.dict")
  # fuzz/<target>.options (optional, sourced): extra libFuzzer flags and ASan options of one target, each stated
  # with its reason there.
  flags=()
  asan_extra=""
  # shellcheck disable=SC1090
  [ -f "$here/fuzz/$t.options" ] && source "$here/fuzz/$t.options"
  log="$build/$t.log"
  rc=0
  ASAN_OPTIONS="$ASAN_OPTIONS${asan_extra:+:$asan_extra}" \
  "$build/fuzz/$t" -max_total_time="$seconds" -runs="$runs" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
    -print_final_stats=1 -artifact_prefix="$build/artifacts/$t-" "${dict[@]}" "${flags[@]}" \
    "$build/corpus/$t" "$here/fuzz/corpus/$t" >"$log" 2>&1 || rc=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  if [ "$rc" = 0 ]; then
    line=$(printf '%-22s %12s executions  ok' "$t" "${execs:-?}")
  else
    line=$(printf '%-22s %12s executions  FINDING (exit %s; log %s)' "$t" "${execs:-?}" "$rc" "$log")
    tail -40 "$log" >&2
    status=1
  fi
  echo "$line"
  summary+="$line"$'\n'
done
echo "dynid fuzz: ${seconds} s / ${runs} runs per target"
printf '%s' "$summary"
exit $status
