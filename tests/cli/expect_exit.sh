#!/usr/bin/env bash
# Run a command and fail unless it exits with the expected status (and, optionally, prints the
# expected text). Used by CTest for the CLI exit-status contract: 0 success, 1 run failed, 2 bad input.
#
#   expect_exit.sh [--stderr TEXT]... [--stdout TEXT]... [--not-stdout TEXT]... <status> <command...>
#
# --stderr TEXT      stderr must contain TEXT (fixed string); repeatable
# --stdout TEXT      stdout must contain TEXT; repeatable
# --not-stdout TEXT  stdout must not contain TEXT; repeatable
# The environment variable EXPECT_STDERR, when set and not empty, works as one more --stderr.
# A status of 128 or more (a signal: a crash) always fails, whatever was expected.
set -u

usage() {
  echo "usage: $0 [--stderr TEXT]... [--stdout TEXT]... [--not-stdout TEXT]... <status> <command...>" >&2
  exit 64
}

want_err=()
want_out=()
not_out=()
if [[ -n "${EXPECT_STDERR:-}" ]]; then want_err+=("$EXPECT_STDERR"); fi
while [[ $# -gt 0 ]]; do
  case "$1" in
    --stderr) [[ $# -ge 2 ]] || usage; want_err+=("$2"); shift 2 ;;
    --stdout) [[ $# -ge 2 ]] || usage; want_out+=("$2"); shift 2 ;;
    --not-stdout) [[ $# -ge 2 ]] || usage; not_out+=("$2"); shift 2 ;;
    --) shift; break ;;
    -*) usage ;;
    *) break ;;
  esac
done
[[ $# -ge 2 ]] || usage
expected="$1"
shift
[[ "$expected" =~ ^[0-9]+$ ]] || usage

tmp="$(mktemp -d)" || exit 70
trap 'rm -rf "$tmp"' EXIT

"$@" >"$tmp/out" 2>"$tmp/err"
status=$?

fail=0
report() {
  echo "FAIL: $*" >&2
  fail=1
}
if [[ $status -ge 128 ]]; then
  report "the command was killed by signal $((status - 128)) (status $status)"
elif [[ $status -ne $expected ]]; then
  report "exit status $status, expected $expected"
fi
for t in ${want_err[@]+"${want_err[@]}"}; do
  grep -qF -- "$t" "$tmp/err" || report "stderr does not contain: $t"
done
for t in ${want_out[@]+"${want_out[@]}"}; do
  grep -qF -- "$t" "$tmp/out" || report "stdout does not contain: $t"
done
for t in ${not_out[@]+"${not_out[@]}"}; do
  grep -qF -- "$t" "$tmp/out" && report "stdout contains: $t"
done

if [[ $fail -ne 0 ]]; then
  echo "command: $*" >&2
  echo "--- stdout (first 40 lines)" >&2
  head -n 40 "$tmp/out" >&2
  echo "--- stderr (first 40 lines)" >&2
  head -n 40 "$tmp/err" >&2
  exit 1
fi
echo "ok: status $status: $*"
exit 0
