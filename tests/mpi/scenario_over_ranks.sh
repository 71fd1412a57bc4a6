#!/bin/bash
# tests/mpi/tests.cmake: a scenario under `hilldem run` over MPI ranks against one process.
#   scenario_over_ranks.sh HILLDEM WORKDIR SCENARIO run N     N ranks: every checkpoint's state digest
#                                                             (the one after make_wet included), the
#                                                             history, the probes and the snapshots
#                                                             (files) are one process's
#   scenario_over_ranks.sh HILLDEM WORKDIR SCENARIO resume [K...]
#                                                             checkpoints K of 4 ranks (default 000005
#                                                             and 000009) resumed on 2 ranks, 1 rank and
#                                                             without mpirun, and the one-process run's
#                                                             last of them resumed on 3 ranks: the
#                                                             uninterrupted run's final digest and history
# MPIRUN (environment): the launcher command line, e.g. "mpiexec --allow-run-as-root --oversubscribe".
set -u
hilldem=$1 work=$2 scenario=$3 mode=$4
rm -rf "$work" && mkdir -p "$work" || exit 1
fail=0
digests() {  # every checkpoint of run folder $1: "NAME DIGEST" lines
  for f in "$1"/checkpoints/ckpt-*.hdc; do
    echo "$(basename "$f") $("$hilldem" inspect "$f" | grep -o 'state digest: [0-9a-f]*')"
  done
}
probes() { grep -E '^(lid_stress|floor_fz|plough_fx) ' "$1"; }
same() {  # what, expected file, actual file
  if ! cmp -s "$2" "$3"; then
    echo "FAIL: $1 differ:"; diff "$2" "$3" | head -20; fail=1
  else
    echo "ok: $1 ($(wc -l < "$2") lines)"
  fi
}
"$hilldem" run "$scenario" -q -o "$work/one" > "$work/one.out" || { echo "FAIL: the one-process run"; exit 1; }
digests "$work/one" > "$work/one.digests"
probes "$work/one.out" > "$work/one.probes"
case $mode in
  run)
    n=$5
    $MPIRUN -np "$n" "$hilldem" run "$scenario" -q -o "$work/ranks" > "$work/ranks.out" || { echo "FAIL: the run on $n ranks"; exit 1; }
    digests "$work/ranks" > "$work/ranks.digests"
    probes "$work/ranks.out" > "$work/ranks.probes"
    same "checkpoint digests on $n ranks" "$work/one.digests" "$work/ranks.digests"
    same "history on $n ranks" "$work/one/history.csv" "$work/ranks/history.csv"
    same "probes on $n ranks" "$work/one.probes" "$work/ranks.probes"
    if [ -d "$work/one/snapshots" ]; then
      if diff -r "$work/one/snapshots" "$work/ranks/snapshots" > /dev/null; then
        echo "ok: snapshots on $n ranks ($(ls "$work/one/snapshots" | wc -l) files)"
      else echo "FAIL: snapshots on $n ranks differ"; diff -rq "$work/one/snapshots" "$work/ranks/snapshots" | head; fail=1; fi
    fi
    ;;
  resume)
    $MPIRUN -np 4 "$hilldem" run "$scenario" -q -o "$work/four" > /dev/null || { echo "FAIL: the run on 4 ranks"; exit 1; }
    final=$(tail -1 "$work/one.digests" | cut -d' ' -f2-)
    shift 4
    ckpts=("$@")
    [ $# -eq 0 ] && ckpts=(000005 000009)
    for k in "${ckpts[@]}"; do
      ckpt="$work/four/checkpoints/ckpt-$k.hdc"
      echo "from $(basename "$ckpt"): $("$hilldem" inspect "$ckpt" | grep -E '^(clock|position)' | tr '\n' ' ')"
      for how in 2 1 plain; do
        out="$work/resumed-$k-$how"
        if [ "$how" = plain ]; then "$hilldem" resume "$ckpt" -q -o "$out" > "$out.out"
        else $MPIRUN -np "$how" "$hilldem" resume "$ckpt" -q -o "$out" > "$out.out"; fi || { echo "FAIL: resume on $how"; fail=1; continue; }
        got=$(tail -1 <(digests "$out") | cut -d' ' -f2-)
        if [ "$got" != "$final" ]; then echo "FAIL: resumed on $how ranks: $got, uninterrupted: $final"; fail=1
        else echo "ok: resumed on $how: $got"; fi
        same "history resumed on $how" "$work/one/history.csv" "$out/history.csv"
        probes "$out.out" > "$out.probes"
        same "probes resumed on $how" "$work/one.probes" "$out.probes"
      done
    done
    # And the one-process run's checkpoint resumed on 3 ranks.
    out="$work/resumed-one-3"
    $MPIRUN -np 3 "$hilldem" resume "$work/one/checkpoints/ckpt-${ckpts[-1]}.hdc" -q -o "$out" > "$out.out" || { echo "FAIL: resume on 3"; fail=1; }
    got=$(tail -1 <(digests "$out") | cut -d' ' -f2-)
    if [ "$got" != "$final" ]; then echo "FAIL: one process's checkpoint resumed on 3 ranks: $got, uninterrupted: $final"; fail=1
    else echo "ok: one process's checkpoint resumed on 3 ranks: $got"; fi
    same "history resumed on 3" "$work/one/history.csv" "$out/history.csv"
    ;;
esac
exit $fail
