#!/usr/bin/env bash
# A lab test stopped by a signal ends after the cycle it is in, with exit status 128 + the signal
# number and a message naming the signal, the step and the packed specimens kept; it writes no
# results (a lab test keeps no checkpoint).
#
#   lab_stop.sh HILLDEM DATA_DIR MODE
#
# MODE
#   t307      `hilldem t307` from the miniature specimen, SIGINT once its test has started: 130
#   packing   `hilldem triaxial` packing the fine grading, SIGTERM once the packed specimen is
#             saved (during finalization or the test): 143, the specimen named for --specimen
set -u
hilldem="$1"
data="$2"
mode="$3"

tmp="$(mktemp -d)" || exit 70
trap 'kill -9 $pid 2>/dev/null; rm -rf "$tmp"' EXIT
fail() {
  echo "FAIL: $*" >&2
  [ -f "$tmp/err" ] && sed 's/^/  stderr: /' "$tmp/err" >&2
  [ -f "$tmp/out" ] && tail -n 5 "$tmp/out" | sed 's/^/  stdout: /' >&2
  exit 1
}

case "$mode" in
  t307)
    "$hilldem" t307 --specimen "$data/labtests/mini_packed.csv" --grading "$data/labtests/fine.csv" --sequences 0,1,7 \
      --cycles 100 --averaged-cycles 2 --conditioning-cycles 100 --no-plot -o "$tmp/run" >"$tmp/out" 2>"$tmp/err" &
    pid=$!
    ready="t307: H0"
    sig=INT
    expected=130
    ;;
  packing)
    "$hilldem" triaxial --grading "$data/labtests/fine.csv" --scale 0.25 --min-grains 0 --cycles 0.1,0.2 --final-strain 5 \
      --no-plot -o "$tmp/run" >"$tmp/out" 2>"$tmp/err" &
    pid=$!
    ready="packed specimen saved"
    sig=TERM
    expected=143
    ;;
  *) fail "unknown mode $mode" ;;
esac

for _ in $(seq 1 1200); do
  grep -q "$ready" "$tmp/out" 2>/dev/null && break
  kill -0 $pid 2>/dev/null || break
  sleep 0.1
done
grep -q "$ready" "$tmp/out" || fail "the test never printed '$ready'"
kill -$sig $pid
wait $pid
status=$?
[ "$status" -eq "$expected" ] || fail "exit status $status, expected $expected"
grep -q "stopped by SIG$sig (stopped on request after step [0-9]" "$tmp/err" || fail "no stop message naming SIG$sig and the step"
case "$mode" in
  t307)
    [ ! -e "$tmp/run/t307_sequences.csv" ] || fail "results were written after the stop"
    grep -q "No packed specimen was saved" "$tmp/err" || fail "the message does not say that no specimen was saved"
    ;;
  packing)
    [ ! -e "$tmp/run/summary.csv" ] || fail "results were written after the stop"
    f=$(ls "$tmp"/run/specimens/*_packed.csv 2>/dev/null | head -n 1)
    [ -n "$f" ] || fail "no packed specimen in the output folder"
    grep -qF "  $f" "$tmp/err" || fail "the message does not name the packed specimen $f"
    grep -q -- "--specimen FILE" "$tmp/err" || fail "the message does not say how to reuse the specimen"
    ;;
esac
echo "stopped by SIG$sig with status $status"
