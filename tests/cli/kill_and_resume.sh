#!/usr/bin/env bash
# A run killed with SIGKILL mid-stage resumes from its last checkpoint and finishes with the same
# result as an uninterrupted run: the same final state (digest of every ball, wall and contact
# column), the same history CSV and snapshot files byte for byte, the same probe table.
#
#   kill_and_resume.sh HILLDEM SCENARIO MODE
#
# MODE
#   step=N        the run kills itself with SIGKILL right after step N (HILLDEM_FAULT_INJECTION)
#   checkpoint=K  it kills itself halfway through writing its K-th checkpoint (a torn temporary file)
#   external      `kill -9` from outside, as soon as the run has written a few checkpoints
#   signal=NAME   `kill -NAME` (INT, TERM, HUP) from outside at the same point: the run finishes its
#                 cycle, writes a checkpoint and exits with 128 + the signal number, saying how to resume
set -u
hilldem="$1"
scenario="$2"
mode="$3"

tmp="$(mktemp -d)" || exit 70
trap 'rm -rf "$tmp"' EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}

newest() { ls "$1"/checkpoints/ckpt-*.hdc 2>/dev/null | sort | tail -n 1; }

# 1. The uninterrupted reference.
"$hilldem" run -q "$scenario" -o "$tmp/ref" >"$tmp/ref.out" 2>"$tmp/ref.err" || fail "the reference run failed: $(cat "$tmp/ref.err")"

# 2. The run that dies.
case "$mode" in
  step=*)
    HILLDEM_FAULT_INJECTION="kill-after-step=${mode#step=}" "$hilldem" run -q "$scenario" -o "$tmp/run" >/dev/null 2>&1
    status=$?
    ;;
  checkpoint=*)
    HILLDEM_FAULT_INJECTION="kill-in-checkpoint=${mode#checkpoint=}" "$hilldem" run -q "$scenario" -o "$tmp/run" >/dev/null 2>&1
    status=$?
    ls "$tmp/run/checkpoints/" | grep -q '\.tmp\.' || fail "no torn temporary checkpoint was left behind"
    ;;
  external)
    "$hilldem" run -q "$scenario" -o "$tmp/run" >/dev/null 2>&1 &
    pid=$!
    # Wait for the 4th checkpoint (the first is written at step 0), then kill without warning.
    for _ in $(seq 1 3000); do
      [ -e "$tmp/run/checkpoints/ckpt-000004.hdc" ] && break
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.01
    done
    kill -9 "$pid" 2>/dev/null
    wait "$pid"
    status=$?
    ;;
  signal=*)
    sig="${mode#signal=}"
    "$hilldem" run -q "$scenario" -o "$tmp/run" >/dev/null 2>"$tmp/run.err" &
    pid=$!
    for _ in $(seq 1 3000); do
      [ -e "$tmp/run/checkpoints/ckpt-000004.hdc" ] && break
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.01
    done
    kill -"$sig" "$pid" 2>/dev/null
    wait "$pid"
    status=$?
    want=$((128 + $(kill -l "$sig")))
    [ "$status" -eq "$want" ] || fail "status $status after SIG$sig, expected $want; it may have finished first ($(cat "$tmp/run.err"))"
    grep -q "stopped by SIG$sig at step" "$tmp/run.err" || fail "no stop message: $(cat "$tmp/run.err")"
    grep -q "continue with: hilldem resume" "$tmp/run.err" || fail "the message does not say how to resume: $(cat "$tmp/run.err")"
    status=137  # (checked; the rest is as after a kill)
    ;;
  *) echo "unknown mode $mode" >&2; exit 64 ;;
esac
[ "$status" -eq 137 ] || fail "the run was not killed by SIGKILL mid-run (status $status); it may have finished first"
[ -n "$(newest "$tmp/run")" ] || fail "no checkpoint survived the kill"
killed_at=$(basename "$(newest "$tmp/run")")

# 3. Resume and finish.
"$hilldem" resume -q "$tmp/run" >"$tmp/resume.out" 2>"$tmp/resume.err" || fail "resume failed: $(cat "$tmp/resume.err")"

# 4. Same result.
a=$("$hilldem" inspect --digest "$(newest "$tmp/ref")") || fail "inspect failed"
b=$("$hilldem" inspect --digest "$(newest "$tmp/run")") || fail "inspect failed"
[ "$a" = "$b" ] || fail "final states differ: digest $a (uninterrupted) vs $b (killed at $killed_at, resumed)"
cmp -s "$tmp/ref/history.csv" "$tmp/run/history.csv" || fail "the history files differ"
diff -r -q -x checkpoints -x .hilldem.lock "$tmp/ref" "$tmp/run" >/dev/null || fail "the output folders differ: $(diff -r -q -x checkpoints -x .hilldem.lock "$tmp/ref" "$tmp/run")"
diff <(grep -v '^history:' "$tmp/ref.out") <(grep -v '^history:' "$tmp/resume.out") >/dev/null || fail "the probe tables differ"
echo "ok: killed ($mode) after $killed_at, resumed; final state $b, history and snapshots identical"
