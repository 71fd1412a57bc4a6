#!/bin/sh
# hilldem on 2 threads against 1 thread on the 100,800-sphere bed.
#
#   bench/thread_scaling.sh [rounds] [steps] [replicate] [threads]
#
# Each round runs `hilldem bench` with `threads` threads (default 2), then with one, back to back, and
# prints both rates and their ratio; the end line gives the median of the rounds' ratios and the ratio
# of the best run of each. The machines here are shared and change speed by tens of per cent within
# minutes (a run that straddles a change reads as 0.7 or 1.4 x), so only rounds side by side compare,
# and more rounds give a steadier median. Results do not depend on the thread count (bitwise; test
# Threads.OneAndTwoThreadsGiveBitwiseIdenticalResults), only the time does.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
rounds=${1:-8}
steps=${2:-300}
rep=${3:-3}
threads=${4:-2}
hilldem=${HILLDEM:-$root/build/hilldem}
[ -x "$hilldem" ] || "$root/scripts/setup.sh" >/dev/null

rate() { "$hilldem" bench --data "$here/bed_settled.data" --replicate "$rep" --steps "$steps" --threads "$1" |
  sed 's/.*particle_steps_per_s=\([^ ]*\).*/\1/'; }
pairs=""
k=0
while [ $k -lt "$rounds" ]; do
  k=$((k + 1))
  many=$(rate "$threads")
  one=$(rate 1)
  echo "round $k: threads=$threads particle_steps_per_s=$many  threads=1 particle_steps_per_s=$one  ratio=$(python3 -c "print('%.2f' % ($many/$one))")"
  pairs="$pairs $many:$one"
done
python3 - "$threads" "$rep" $pairs <<'EOF'
import statistics, sys
threads, rep = sys.argv[1], int(sys.argv[2])
pairs = [tuple(map(float, p.split(':'))) for p in sys.argv[3:]]
ratios = [m / o for m, o in pairs]
best = max(m for m, _ in pairs) / max(o for _, o in pairs)
print('threads %s / 1 (%d spheres, %d rounds): median %.2f, range %.2f-%.2f, best against best %.2f'
      % (threads, rep * rep * 11200, len(pairs), statistics.median(ratios), min(ratios), max(ratios), best))
EOF
