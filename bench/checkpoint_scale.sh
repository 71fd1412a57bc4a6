#!/usr/bin/env bash
# Checkpoint size and write/read time on the bench bed (bench/bed_settled.data, 11,200 spheres)
# replicated N x N in x-y: 5 steps with checkpoints at the start, the stage end and the end. Prints
# one line per checkpoint written and the time `hilldem inspect --digest` takes to read the last.
# The write/read times come from hilldem's own progress lines (states of 100 MB or more); the run is
# also timed without checkpoints, so the difference is what the checkpoints cost in all.
#
#   bench/checkpoint_scale.sh HILLDEM N [OUT_DIR]     # N = 3: 100,800 spheres; N = 9: 907,200
#
# PERIODIC=0 drops the periodic x-y box (the grains at the sides then have fewer neighbours), so that
# the checkpoints save the contacts only (docs/checkpoints.md).
set -eu
hilldem="$1"
n="$2"
out="${3:-out/checkpoint_scale_$n}"
here="$(cd "$(dirname "$0")" && pwd)"
mkdir -p "$out"
cat >"$out/bed.toml" <<TOML
title = "bench bed x $n x $n: checkpoint size and time"
[simulation]
timestep = 1e-6
local_damping = 0.7
gravity = [0.0, 0.0, -9.81]
$([ "${PERIODIC:-1}" = 0 ] || echo 'periodic = ["x", "y"]')
skin = 1e-3
[checkpoints]
every_seconds = 0
stage_end_min_seconds = 0
keep = 3
[[material]]
name = "granite"
density = 2650
young_mod = 29e9
pois_ratio = 0.15
[[packing]]
file = "$here/bed_settled.data"
material = "granite"
replicate = [$n, $n, 1]
[[wall]]
name = "floor"
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[contact_model]]
name = "grain-grain hill"
between = "ball-ball"
model = "hill"
fric_coef = 0.4
damp_con = 0.07
[[contact_model]]
name = "grain-floor linear"
between = "ball-wall"
model = "linear"
emod = 29e9
kratio = 1.0
fric = 0.4
[[stage]]
type = "cycle"
steps = 5
TOML
/usr/bin/time -f "run without checkpoints: %e s wall, %M kB peak memory" "$hilldem" run -q --no-checkpoints "$out/bed.toml" -o "$out/plain" 2>&1 >/dev/null | grep -E "run" || true
rm -rf "$out/plain"
/usr/bin/time -f "run with checkpoints: %e s wall, %M kB peak memory" "$hilldem" run "$out/bed.toml" -o "$out/run" 2>&1 >/dev/null | grep -E "checkpoint:.*done|run with" || true
ls -l "$out/run/checkpoints/"
last="$(ls "$out/run/checkpoints/"ckpt-*.hdc | tail -n 1)"
"$hilldem" inspect "$last" 2>/dev/null | grep -E "bodies|sections"
/usr/bin/time -f "inspect --digest: %e s wall, %M kB peak memory" "$hilldem" inspect --digest "$last" 2>&1 | grep -E "done|inspect"
