#!/usr/bin/env bash
# The training set of the profile-guided build (scripts/setup.sh, CMakeLists.txt HILLDEM_PGO): runs an
# instrumented hilldem on what users run, so that its profiles weigh the hot paths as they are used.
#   scripts/pgo_train.sh HILLDEM_BINARY
# About half a minute. Outputs go to a temporary folder that is removed.
set -euo pipefail
cd "$(dirname "$0")/.."
hilldem="$1"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The memo's test problems: two grains (linear, hill, shear dashpot), the moisture test, the
# 27-ball assembly, restitution.
"$hilldem" verify >/dev/null
# The dense bed: batched hill ball-ball contacts, a linear floor, periodic images; one and two threads,
# and replicated 3 x 3 (100,800 spheres), where the force pass asks for rows ahead (more than 2^17 rows).
"$hilldem" bench --steps 200 --warmup 20 --threads 1 >/dev/null
"$hilldem" bench --steps 40 --warmup 10 --threads 2 >/dev/null
"$hilldem" bench --replicate 3 --steps 20 --warmup 5 --threads 1 >/dev/null
# Lab tests at a small scale: genesis (boundary-contraction packing), wetting, servo-controlled walls,
# the load-unload cycles; hill wet and linear.
"$hilldem" triaxial --scale 0.3 --wet --cycles 0.02 --final-strain 0.05 --no-plot -q --threads 1 -o "$work/wet" >/dev/null
"$hilldem" triaxial --scale 0.3 --material linear --cycles 0.02 --final-strain 0.05 --no-plot -q --threads 1 \
  -o "$work/linear" >/dev/null
