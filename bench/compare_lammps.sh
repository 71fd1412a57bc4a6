#!/bin/sh
# hilldem against LAMMPS GRANULAR on the same dense bed, side by side, one thread each.
#
#   bench/compare_lammps.sh [steps_small] [steps_large] [threads] [repeats]
#
# Both codes read bench/bed_settled.data (11,200 granite spheres, radii 4-6 mm, periodic in x and y,
# floor at z = 0, gravity, dt = 1e-6 s; LAMMPS data format), replicated 3 x 3 for 100,800 spheres.
# LAMMPS runs bench/lammps/in.bench with pair granular (Hertz-Mindlin, Tsuji e = 0.9, mu = 0.4);
# hilldem runs `hilldem bench` (hill model: E 29 GPa, nu 0.15, mu 0.4, damp_con 0.07 ~ e = 0.906).
# Prints one line per run and the ratio hilldem / LAMMPS in particle-steps per second. With repeats > 1
# the two codes run in turn (L H L H ...) and two ratios are printed: that of the best run of each,
# and the median of the runs' own ratios (each hilldem run against the LAMMPS run before it). The
# machines here are shared, and their speed drifts by tens of per cent within minutes: when it
# changes between runs, best against best compares two different machines, the median less so.
# LAMMPS is Debian's `lammps` package (installed here if missing).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
small=${1:-2000}
large=${2:-500}
threads=${3:-1}
repeats=${4:-1}
hilldem=${HILLDEM:-$root/build/hilldem}
[ -x "$hilldem" ] || "$root/scripts/setup.sh" >/dev/null
command -v lmp >/dev/null 2>&1 || { echo "installing Debian lammps" >&2; apt-get install -y -q lammps >/dev/null; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$here/lammps/in.bench" "$here/lammps/pair.granular" "$here/lammps/parse_log.sh" "$work/"
cp "$here/bed_settled.data" "$work/pack_base.data"   # in.bench reads pack_base.data
export OMP_NUM_THREADS=$threads

best() { sort -g | tail -1; }
for rep in 1 3; do
  steps=$small; [ "$rep" = 3 ] && steps=$large
  warm=$((steps / 5))
  : > "$work/lmp.rates"; : > "$work/hd.rates"
  k=0
  while [ $k -lt "$repeats" ]; do
    k=$((k + 1))
    (cd "$work" && lmp -in in.bench -var rep $rep -var nwarm $warm -var nsteps $steps -var model granular \
       -log log.$rep -screen none)
    lmp_line=$(sh "$work/parse_log.sh" "$work/log.$rep")
    hd_line=$("$hilldem" bench --data "$here/bed_settled.data" --replicate $rep --steps $steps --warmup $warm \
       --threads "$threads")
    echo "lammps  $lmp_line"
    echo "hilldem $hd_line"
    echo "$lmp_line" | sed 's/.*particle_steps_per_s=\([^ ]*\).*/\1/' >> "$work/lmp.rates"
    echo "$hd_line" | sed 's/.*particle_steps_per_s=\([^ ]*\).*/\1/' >> "$work/hd.rates"
  done
  lmp_rate=$(best < "$work/lmp.rates")
  hd_rate=$(best < "$work/hd.rates")
  python3 -c "print('ratio hilldem/lammps (%d spheres, %s thread(s), best of %s each): %.2f' % ($rep*$rep*11200, '$threads', '$repeats', $hd_rate/$lmp_rate))"
  # The median of the runs' own ratios (each hilldem run against the LAMMPS run just before it):
  # steadier than best against best when the machine changes speed between runs.
  paste "$work/hd.rates" "$work/lmp.rates" | python3 -c "
import statistics, sys
r = [float(h) / float(l) for h, l in (line.split() for line in sys.stdin)]
print('ratio hilldem/lammps (%d spheres, %s thread(s), median of %d side-by-side runs): %.2f (range %.2f-%.2f)'
      % ($rep * $rep * 11200, '$threads', len(r), statistics.median(r), min(r), max(r)))"
done
