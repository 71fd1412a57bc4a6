#!/usr/bin/env bash
# What a run leaves in its output folder stays whole and true (docs/checkpoints.md): one run per
# folder, resume checks what it continues, torn files are cleaned, many short stages stay cheap, and
# running out of memory says where and how much.
#
#   reliability.sh HILLDEM SCENARIO CASE
#
# SCENARIO is the restart bed (tests/data/restart/wet_servo_box.toml). CASE is one of the functions
# below (case_<name>).
set -u
hilldem="$1"
scenario="$2"
case_name="$3"

tmp="$(mktemp -d)" || exit 70
cleanup() {
  [ -n "${held_pid:-}" ] && kill -CONT "$held_pid" 2>/dev/null && wait "$held_pid" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
# expect STATUS TEXT... -- COMMAND...: the command exits with STATUS and its stderr holds every TEXT.
expect() {
  local want="$1"
  shift
  local texts=()
  while [ "$1" != "--" ]; do texts+=("$1"); shift; done
  shift
  "$@" >"$tmp/out" 2>"$tmp/err"
  local status=$?
  [ "$status" -eq "$want" ] || fail "exit status $status, expected $want: $* (stderr: $(head -c 2000 "$tmp/err"))"
  for t in ${texts[@]+"${texts[@]}"}; do
    grep -qF -- "$t" "$tmp/err" || fail "stderr lacks '$t': $(head -c 2000 "$tmp/err")"
  done
}
# A run killed (SIGKILL) mid-translate, leaving its output folder as a crash leaves it.
killed_run() {
  HILLDEM_FAULT_INJECTION="kill-after-step=5150" "$hilldem" run -q "$scenario" -o "$1" >/dev/null 2>&1
  [ $? -eq 137 ] || fail "the run was not killed mid-run"
}
reference() { "$hilldem" run -q "$scenario" -o "$tmp/ref" >/dev/null 2>&1 || fail "the reference run failed"; }
same_outputs() {
  cmp -s "$tmp/ref/history.csv" "$1/history.csv" || fail "$1/history.csv differs from the uninterrupted run's"
  diff -r -q -x checkpoints -x .hilldem.lock "$tmp/ref" "$1" >/dev/null || fail "the output folders differ: $(diff -r -q -x checkpoints -x .hilldem.lock "$tmp/ref" "$1")"
}

# Item 1: a folder whose lock another process holds is refused with exit status 2, naming the holder.
case_lock_held() {
  mkdir -p "$tmp/run"
  exec 9>"$tmp/run/.hilldem.lock"
  flock -n 9 || fail "cannot take the lock for the test"
  printf 'pid 4242\nhost testhost\ncommand hilldem run other.toml\n' >&9
  expect 2 "in use by another hilldem process" "pid 4242" "host testhost" "command hilldem run other.toml" -- \
    "$hilldem" run -q "$scenario" -o "$tmp/run"
  [ ! -e "$tmp/run/history.csv" ] || fail "the refused run wrote its history"
  expect 2 "in use by another hilldem process" -- "$hilldem" triaxial -q --no-plot -o "$tmp/run"
  exec 9>&-
  # Released (the holder ended): the folder is free again, the old lock file is no obstacle.
  expect 0 -- "$hilldem" run -q "$scenario" -o "$tmp/run"
}

# Item 1 with two real runs: the second, started while the first is running, is refused; the
# first finishes with the uninterrupted history, not a splice of the two.
case_lock_two_runs() {
  reference
  "$hilldem" run -q "$scenario" -o "$tmp/run" >/dev/null 2>&1 &
  held_pid=$!
  for _ in $(seq 1 2000); do grep -qs "pid $held_pid" "$tmp/run/.hilldem.lock" && break; sleep 0.005; done
  kill -STOP "$held_pid" 2>/dev/null || fail "the first run ended before the test could hold it"
  for _ in $(seq 1 400); do grep -q '^State:.*T' "/proc/$held_pid/status" && break; sleep 0.005; done
  grep -q '^State:.*T' "/proc/$held_pid/status" || fail "the first run is not stopped"
  expect 2 "in use by another hilldem process" "pid $held_pid" "run -q" -- "$hilldem" run -q "$scenario" -o "$tmp/run"
  expect 2 "in use by another hilldem process" "pid $held_pid" -- "$hilldem" resume -q "$tmp/run"
  kill -CONT "$held_pid"
  wait "$held_pid" || fail "the first run failed"
  held_pid=
  same_outputs "$tmp/run"
}

# Item 4: a second signal stops at once. Two signals are made pending while the run is stopped
# (SIGSTOP), so both arrive together when it continues: the first asks for the graceful stop, the
# second kills the process by its default action (status 128 + the signal, no stop message, no new
# checkpoint).
case_second_signal() {
  "$hilldem" run -q "$scenario" -o "$tmp/run" >/dev/null 2>"$tmp/run.err" &
  held_pid=$!
  # (The lock is taken after the handlers are installed.)
  for _ in $(seq 1 2000); do grep -qs "pid $held_pid" "$tmp/run/.hilldem.lock" && break; sleep 0.005; done
  kill -STOP "$held_pid" 2>/dev/null || fail "the run ended before the test could hold it"
  for _ in $(seq 1 400); do grep -q '^State:.*T' "/proc/$held_pid/status" && break; sleep 0.005; done
  local before
  before="$(ls "$tmp/run/checkpoints")"
  kill -TERM "$held_pid"
  kill -INT "$held_pid"
  kill -CONT "$held_pid"
  wait "$held_pid"
  local status=$?
  held_pid=
  [ "$status" -eq 130 ] || [ "$status" -eq 143 ] || fail "status $status, expected 130 or 143 (killed by the second signal)"
  ! grep -q "stopped by" "$tmp/run.err" || fail "the second signal did not stop at once: $(cat "$tmp/run.err")"
  [ "$(ls "$tmp/run/checkpoints" | grep -v '\.tmp\.')" = "$(echo "$before" | grep -v '\.tmp\.')" ] || fail "a checkpoint was written after the second signal"
}

# Item 2: resume refuses a history that is shorter, missing or changed, and a snapshot index that
# lists files that are gone, instead of silently restarting them.
case_resume_checks() {
  killed_run "$tmp/a"
  cp -r "$tmp/a" "$tmp/b"; cp -r "$tmp/a" "$tmp/c"; cp -r "$tmp/a" "$tmp/d"
  truncate -s 100 "$tmp/a/history.csv"
  expect 2 "history.csv: the history file has 100 bytes, shorter than" "ckpt-" -- "$hilldem" resume -q "$tmp/a"
  rm "$tmp/b/history.csv"
  expect 2 "history.csv: the history file is missing" -- "$hilldem" resume -q "$tmp/b"
  sed -i '3s/^/9/' "$tmp/c/history.csv"
  expect 2 "are not the rows the run had written" "CRC-32" -- "$hilldem" resume -q "$tmp/c"
  rm "$tmp/d/snapshots/balls_000001.vtp"
  expect 2 "balls_000001.vtp: missing; the snapshot index" -- "$hilldem" resume -q "$tmp/d"
  expect 2 "balls_000001.vtp: missing" -- "$hilldem" resume -q "$tmp/d" -o "$tmp/d2"
}

# Item 2: resume -o NEWDIR gives a folder complete on its own (the history from the start, every
# snapshot, a checkpoint to resume from), equal to the uninterrupted run's.
case_resume_elsewhere() {
  reference
  killed_run "$tmp/a"
  expect 0 -- "$hilldem" resume -q "$tmp/a" -o "$tmp/new"
  same_outputs "$tmp/new"
  ls "$tmp/new/checkpoints/" | grep -q '^ckpt-.*\.hdc$' || fail "no checkpoint in the new folder"
  # The folder resumed from is left as it was: its history still ends where the kill left it.
  [ "$(tail -n 1 "$tmp/a/history.csv" | cut -d, -f1)" -le 5150 ] || fail "the old folder's history was continued"
}

# Item 3: fragments of files being written when a run was killed (NAME.tmp.PID) are removed from
# every output folder on resume, not only from checkpoints/; other files stay.
case_torn_files() {
  reference
  killed_run "$tmp/run"
  echo torn >"$tmp/run/snapshots/balls_000004.vtp.tmp.99999"
  echo torn >"$tmp/run/snapshots/balls.pvd.tmp.99999"
  echo torn >"$tmp/run/checkpoints/ckpt-000015.hdc.tmp.99999"
  echo mine >"$tmp/run/notes.tmp.txt"
  expect 0 -- "$hilldem" resume -q "$tmp/run"
  [ -z "$(find "$tmp/run" -name '*.tmp.[0-9]*')" ] || fail "torn files left: $(find "$tmp/run" -name '*.tmp.[0-9]*')"
  [ -e "$tmp/run/notes.tmp.txt" ] || fail "a file that is no torn write was removed"
  rm "$tmp/run/notes.tmp.txt"
  same_outputs "$tmp/run"
}

# Item 5: with the default stage_end_min_seconds (60 s) a scenario of many one-step stages writes no
# checkpoint at their ends (only the start and the final one); with 0 it writes one at each.
case_stage_end_budget() {
  {
    sed -n '/^\[\[material\]\]/,/^\[\[stage\]\]/p' "$scenario" | sed '$d'
    for k in $(seq 1 200); do printf '[[stage]]\ntype = "cycle"\nsteps = 1\n\n'; done
  } >"$tmp/short.toml"
  expect 0 -- "$hilldem" run -q "$tmp/short.toml" -o "$tmp/budget"
  [ "$(ls "$tmp/budget/checkpoints")" = "ckpt-000001.hdc
ckpt-000002.hdc" ] || fail "expected the start and final checkpoints only, got: $(ls "$tmp/budget/checkpoints" | tr '\n' ' ')"
  printf '[checkpoints]\nstage_end_min_seconds = 0\n' >>"$tmp/short.toml"
  expect 0 -- "$hilldem" run -q "$tmp/short.toml" -o "$tmp/every"
  ls "$tmp/every/checkpoints" | grep -q 'ckpt-000201.hdc' || fail "expected 201 checkpoints, got: $(ls "$tmp/every/checkpoints" | tr '\n' ' ')"
  expect 2 "checkpoints.stage_end_min_seconds" "[0, 1e+09]" -- sh -c \
    "sed 's/stage_end_min_seconds = 0/stage_end_min_seconds = -1/' '$tmp/short.toml' > '$tmp/bad.toml' && '$hilldem' check '$tmp/bad.toml'"
}

# Item 10: out of memory names the phase and the size (exit status 1), not a bare std::bad_alloc.
case_out_of_memory() {
  {
    sed -n '/^\[\[material\]\]/,/^pois_ratio/p' "$scenario"
    printf '[[ball_grid]]\nfirst_id = 1\norigin = [0, 0, 0]\ncounts = [300, 300, 300]\nspacing = 0.01\nradius = 0.004\nmaterial = "granite"\n'
  } >"$tmp/huge.toml"
  expect 1 "out of memory while reading" "ball_grid[1].counts" "2.7e+07 balls" "MB needed" -- \
    sh -c "ulimit -v 1000000 && exec '$hilldem' check '$tmp/huge.toml'"
}

declare -F "case_$case_name" >/dev/null || { echo "unknown case $case_name" >&2; exit 64; }
"case_$case_name"
echo "ok: $case_name"
