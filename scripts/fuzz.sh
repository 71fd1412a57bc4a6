#!/usr/bin/env bash
# Fuzz the scenario reader and the checkpoint reader for a bounded time, with libFuzzer,
# AddressSanitizer and UndefinedBehaviorSanitizer (fuzz/). Builds the clang tree first (incremental).
#
#   scripts/fuzz.sh [seconds-per-target] [build-dir]      (defaults: 25, build-fuzz)
#
# Seeds: the examples and the malformed-input corpora (tests/data/bad, tests/data/bad_checkpoints)
# plus fuzz/corpus/; new interesting inputs accumulate in <build-dir>/corpus/ between runs. Passes
# when each target ran at least HILLDEM_FUZZ_MIN_RUNS inputs (default 10000; on a busy machine in up
# to four rounds of the given seconds) with no crash, hang,
# leak, out-of-memory or sanitizer report; prints the counts. A finding is kept in
# <build-dir>/findings/ (add it to fuzz/corpus/ once fixed: the replay tests then keep it).
# Exit status: 0 pass, 1 a finding or too few runs, 77 skipped (no clang/libFuzzer: the fuzz build
# is optional where clang is missing; scripts/setup.sh installs clang and libclang-rt-14-dev).
set -uo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-25}"
build="${2:-build-fuzz}"
min_runs="${HILLDEM_FUZZ_MIN_RUNS:-10000}"

cxx="$(command -v clang++ || command -v clang++-14 || true)"
if [ -z "$cxx" ] || ! echo 'extern "C" int LLVMFuzzerTestOneInput(const unsigned char*, unsigned long) { return 0; }' | "$cxx" -x c++ -fsanitize=fuzzer,address,undefined -o /dev/null - >/dev/null 2>&1; then
  echo "fuzz: SKIPPED: clang++ with libFuzzer and the sanitizers is not available (Debian: clang libclang-rt-14-dev)"
  exit 77
fi
echo "fuzz: building the targets with $cxx (ASan + UBSan) in $build"
if ! { CXX="$cxx" cmake -S fuzz -B "$build" >"$build.configure.log" 2>&1 &&
       cmake --build "$build" -j"$(nproc)" --target fuzz_scenario fuzz_checkpoint >"$build.build.log" 2>&1; }; then
  echo "fuzz: FAILED to build (see $build.configure.log, $build.build.log)"
  tail -n 30 "$build.build.log" 2>/dev/null
  exit 1
fi

status=0
run() {
  local target="$1" dict="$2"
  shift 2
  mkdir -p "$build/corpus/$target" "$build/findings"
  local log="$build/$target.log"
  # A loaded machine (CI beside other jobs) runs fewer inputs per second: up to four rounds of
  # `seconds` each, until the target has run min_runs inputs in all (each round resumes from the
  # corpus the last one left). A finding ends it at once.
  local total=0 round rc runs
  for round in 1 2 3 4; do
    # -rss_limit_mb also caps single allocations; -timeout flags any input slower than 10 s as a hang.
    "$build/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      ${dict:+-dict="$dict"} -artifact_prefix="$build/findings/$target-" "$build/corpus/$target" "$@" >"$log" 2>&1
    rc=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    total=$((total + ${runs:-0}))
    if [ $rc -ne 0 ]; then
      echo "fuzz: $target: FINDING after $total inputs (exit $rc); the input is in $build/findings/:"
      grep -E "ERROR|SUMMARY|hilldem fuzz|deadly|Test unit written" "$log" | head -n 12
      status=1
      return
    fi
    [ "$total" -ge "$min_runs" ] || [ "$round" -eq 4 ] && break
    echo "fuzz: $target: $total inputs after round $round of ${seconds} s (at least $min_runs required): the machine is busy; one more round"
  done
  if [ "$total" -lt "$min_runs" ]; then
    echo "fuzz: $target: only $total inputs in $round rounds of ${seconds} s (at least $min_runs required)"
    status=1
  else
    echo "fuzz: $target: $total inputs in $round round(s) of ${seconds} s, no crash, hang, leak or sanitizer report ($(grep -c . <(ls "$build/corpus/$target")) corpus entries)"
  fi
}
run scenario fuzz/scenario.dict fuzz/corpus/scenario examples tests/data/bad tests/data/restart tests/data/cli
run checkpoint "" fuzz/corpus/checkpoint tests/data/bad_checkpoints
exit $status
