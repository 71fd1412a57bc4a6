#!/bin/bash
# tests/mpi/tests.cmake: `hilldem triaxial` and `hilldem t307` under mpirun -np N against one process.
#   lab_over_ranks.sh HILLDEM WORKDIR DATA N
# On the miniature specimen (DATA/labtests/mini_packed.csv, grading DATA/labtests/fine.csv): a wet
# triaxial case at two confinements (two cases, each a copy of the specimen attached on its own:
# finalize, make_wet, the confining phase at 100 kPa, one cycle, the final load), a short T 307 (conditioning and four
# sequences) and a genesis from the seed in a small vessel (--pack-only). Every CSV file they write
# (histories, loops, the summary less its two columns of seconds, the sequences, the cycles, the fit,
# the realised grading, the packed specimen) is byte for byte the one-process run's. The same for a
# genesis of clumps (a mix of two templates) and a wet triaxial case on the specimen it packs.
# MPIRUN (environment): the launcher command line, e.g. "mpiexec --allow-run-as-root --oversubscribe".
set -u
hilldem=$1 work=$2 data=$3 n=$4
rm -rf "$work" && mkdir -p "$work" || exit 1
fail=0
same() {  # what, expected file, actual file
  if [ ! -s "$2" ]; then echo "FAIL: $1: $2 is missing or empty"; fail=1
  elif ! cmp -s "$2" "$3"; then echo "FAIL: $1 differ:"; diff "$2" "$3" | head -20; fail=1
  else echo "ok: $1 ($(wc -l < "$2") lines)"; fi
}
drop_seconds() { awk -F, -v OFS=, '{NF -= 2; print}' "$1"; }  # summary.csv's packing_seconds and seconds
triaxial=(triaxial --specimen "$data/labtests/mini_packed.csv" --grading "$data/labtests/fine.csv" --wet --cycles 0.02
          --final-strain 0.06 --strain-rate 0.1 --final-strain-rate 0.5 --confinement 100e3,150e3 --threads 1 --no-plot -q)
t307=(t307 --specimen "$data/labtests/mini_packed.csv" --grading "$data/labtests/fine.csv" --sequences 0,1,7,11,14 --cycles 2
      --averaged-cycles 1 --conditioning-cycles 1 --pulse-duration 5e-3 --rest-duration 2e-3 --settle-duration 1e-3
      --threads 1 --no-plot -q)
genesis=(triaxial --pack-only --grading "$data/labtests/fine.csv" --scale 0.15 --seed 42 --threads 1 --no-plot -q)
# Clumps: a genesis of a 50/50 mix of elongated pairs and spheres, then a wet triaxial case on it.
clumps=(--clump-template elongated2:0.5,sphere:0.5)
clump_triaxial=(triaxial --grading "$data/labtests/fine.csv" "${clumps[@]}" --wet --cycles 0.02 --final-strain 0.04
                --strain-rate 0.1 --final-strain-rate 0.5 --confinement 100e3 --threads 1 --no-plot -q)
for run in one ranks; do
  launch=(); [ "$run" = ranks ] && launch=($MPIRUN -np "$n")
  "${launch[@]}" "$hilldem" "${triaxial[@]}" -o "$work/$run/triaxial" > "$work/$run.triaxial.out" 2>&1 \
    || { echo "FAIL: triaxial ($run)"; cat "$work/$run.triaxial.out"; exit 1; }
  "${launch[@]}" "$hilldem" "${t307[@]}" -o "$work/$run/t307" > "$work/$run.t307.out" 2>&1 \
    || { echo "FAIL: t307 ($run)"; cat "$work/$run.t307.out"; exit 1; }
  "${launch[@]}" "$hilldem" "${genesis[@]}" -o "$work/$run/genesis" > "$work/$run.genesis.out" 2>&1 \
    || { echo "FAIL: genesis ($run)"; cat "$work/$run.genesis.out"; exit 1; }
  "${launch[@]}" "$hilldem" "${genesis[@]}" "${clumps[@]}" -o "$work/$run/clumps" > "$work/$run.clumps.out" 2>&1 \
    || { echo "FAIL: genesis of clumps ($run)"; cat "$work/$run.clumps.out"; exit 1; }
  "${launch[@]}" "$hilldem" "${clump_triaxial[@]}" --specimen "$work/one/clumps/specimens/fine_hill_packed.csv" \
    -o "$work/$run/clump_triaxial" > "$work/$run.clump_triaxial.out" 2>&1 \
    || { echo "FAIL: triaxial of clumps ($run)"; cat "$work/$run.clump_triaxial.out"; exit 1; }
  drop_seconds "$work/$run/triaxial/summary.csv" > "$work/$run.summary.csv"
done
for c in fine_Hill_wet_100kPa fine_Hill_wet_150kPa; do
  for f in history.csv loops.csv gsd.csv; do
    same "triaxial $c/$f on $n ranks" "$work/one/triaxial/$c/$f" "$work/ranks/triaxial/$c/$f"
  done
done
same "triaxial summary.csv (less its seconds) on $n ranks" "$work/one.summary.csv" "$work/ranks.summary.csv"
for f in t307_sequences.csv t307_cycles.csv t307_fit.csv; do
  same "t307 $f on $n ranks" "$work/one/t307/$f" "$work/ranks/t307/$f"
done
for f in fine_hill_packed.csv fine_hill_gsd.csv; do
  same "genesis specimens/$f on $n ranks" "$work/one/genesis/specimens/$f" "$work/ranks/genesis/specimens/$f"
done
same "genesis of clumps specimens/fine_hill_packed.csv on $n ranks" "$work/one/clumps/specimens/fine_hill_packed.csv" \
  "$work/ranks/clumps/specimens/fine_hill_packed.csv"
for f in history.csv loops.csv; do
  same "triaxial of clumps $f on $n ranks" "$work/one/clump_triaxial/fine_Hill_wet/$f" \
    "$work/ranks/clump_triaxial/fine_Hill_wet/$f"
done
# One process's lines once: rank 0 alone prints.
for what in triaxial t307; do
  a=$(grep -c . "$work/one.$what.out"); b=$(grep -c . "$work/ranks.$what.out")
  [ "$a" = "$b" ] && echo "ok: $what prints $a lines on $n ranks" || { echo "FAIL: $what prints $b lines on $n ranks, $a in one process"; fail=1; }
done
exit $fail
