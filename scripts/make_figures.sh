#!/usr/bin/env bash
# Regenerate the figures in docs/figures/ (shown in the README) from fresh runs of the examples:
#   fig10_two_grains_linear.png  force-displacement of the linear two-grain example (memo Fig. 10)
#   fig11_two_grains_hill.png    the same for the hill model (memo Fig. 11)
#   fig12_stiffness.png          linear against hill normal force, log-log (memo Fig. 12)
#   fig06_moisture.png           moisture force against gap in the moisture test (memo Fig. 6)
#   servo_lid_stress.png         a generic two-column plot: lid stress against lid travel (restart bed)
# Needs build/hilldem (scripts/setup.sh) and Debian's python3-matplotlib.
#   scripts/make_figures.sh [output-folder]     (default docs/figures)
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-docs/figures}"
hilldem=build/hilldem
plot="/usr/bin/python3 scripts/plot_history.py"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$out"
for e in two_grains_linear two_grains_hill moisture_test; do
  "$hilldem" run -q "examples/$e.toml" -o "$tmp/$e" --no-checkpoints >/dev/null
done
"$hilldem" run -q tests/data/restart/wet_servo_box.toml -o "$tmp/bed" --no-checkpoints >/dev/null
# Stages A (100 steps) and B (200 steps) of the two-grain examples: steps 0-300.
$plot force-displacement "$tmp/two_grains_linear/history.csv" --steps 0:300 -o "$out/fig10_two_grains_linear.png" \
  --title "Two granite grains, linear model: force against displacement (memo Fig. 10)"
$plot force-displacement "$tmp/two_grains_hill/history.csv" --steps 0:300 -o "$out/fig11_two_grains_hill.png" \
  --title "Two granite grains, hill model: force against displacement (memo Fig. 11)"
$plot stiffness "$tmp/two_grains_hill/history.csv" "$tmp/two_grains_linear/history.csv" --steps 0:100 \
  -o "$out/fig12_stiffness.png"
# psi = 200 kPa, R_o = min(7.5, 5) mm; from step 1 (the grains are wetted at step 0).
$plot moisture "$tmp/moisture_test/history.csv" --suction 200e3 --r-o 5e-3 --steps 1: -o "$out/fig06_moisture.png"
$plot xy "$tmp/bed/history.csv" --x lid_z --x-offset first --x-scale=-1e3 --x-unit mm --x-label "lid travel" \
  --y lid_stress --y-scale 1e-3 --y-unit kPa --y-label "lid stress" --steps 500: \
  --title "Servo-driven lid: stress against travel (tests/data/restart)" -o "$out/servo_lid_stress.png"
