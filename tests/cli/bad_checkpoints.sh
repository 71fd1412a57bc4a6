#!/usr/bin/env bash
# Every file of the malformed-checkpoint corpus makes `hilldem resume` exit with status 2 and a
# message that names the file; `hilldem inspect` (which shows blow-up states and does not rebuild the
# run) either describes the file or refuses it the same way. Never a crash, never another status.
#   bad_checkpoints.sh HILLDEM CORPUS_DIR
set -u
hilldem="$1"
dir="$2"
tmp="$(mktemp -d)" || exit 70
trap 'rm -rf "$tmp"' EXIT
n=0
bad=0
for f in "$dir"/*.hdc; do
  for cmd in resume inspect; do
    # resume writes its outputs next to the checkpoint unless told otherwise: keep the corpus clean.
    if [ "$cmd" = resume ]; then "$hilldem" resume -q -o "$tmp/out" "$f" >"$tmp/out.txt" 2>"$tmp/err.txt"
    else "$hilldem" inspect "$f" >"$tmp/out.txt" 2>"$tmp/err.txt"; fi
    status=$?
    name=$(basename "$f")
    if [ "$cmd" = inspect ] && [ "$status" -eq 0 ]; then
      :
    elif [ "$status" -ne 2 ]; then
      echo "FAIL: hilldem $cmd $name: exit status $status, expected 2; stderr: $(head -c 400 "$tmp/err.txt")" >&2
      bad=$((bad + 1))
    elif ! grep -qF "$name" "$tmp/err.txt"; then
      echo "FAIL: hilldem $cmd $name: the message does not name the file: $(head -c 400 "$tmp/err.txt")" >&2
      bad=$((bad + 1))
    fi
    n=$((n + 1))
  done
done
[ "$n" -ge 40 ] || { echo "FAIL: only $n cases: is the corpus there?" >&2; exit 1; }
[ "$bad" -eq 0 ] || exit 1
echo "ok: $n refusals, each exit status 2 with the file named"
