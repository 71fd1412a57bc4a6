#!/usr/bin/env bash
# Writes a broken copy of a packed specimen file, for the CLI tests of `hilldem triaxial --specimen`.
#
#   broken_specimen.sh MODE SOURCE DEST
#
# MODE: one_centre  (the second grain row takes the first's centre)
#       grown       (the grain nearest the vessel axis at mid-height, its radius x 1.3: overlaps its neighbours)
#       poisson     (the first grain's Poisson's ratio 0.7)
#       modulus     (the first grain's Young's modulus 1e300 Pa)
#       tiny        (the first grain's radius 1e-300 m)
#       pressure    (the recorded packing pressure 1.5 kPa: the walls' 150 kPa is far from it)
set -eu
mode=$1 src=$2 dest=$3
mkdir -p "$(dirname "$dest")"
case "$mode" in
  one_centre) awk -F, -v OFS=, 'h==1 && n==0 {x=$2; y=$3; z=$4} h==1 && n==1 {$2=x; $3=y; $4=z} h==1 {n++} $1=="id" {h=1} {print}' "$src" > "$dest" ;;
  grown) awk -F, -v OFS=, '
      $1=="vessel_bottom[m]" {b=$2} $1=="vessel_top[m]" {t=$2}
      {line[NR]=$0} h==1 {d=$2*$2+$3*$3+($4-(b+t)/2)^2; if (best=="" || d<bd) {best=NR; bd=d}} $1=="id" {h=1}
      END {for (i=1; i<=NR; i++) {if (i==best) {split(line[i], c, ","); c[5]=c[5]*1.3; line[i]=c[1]; for (k=2; k<=8; k++) line[i]=line[i] "," c[k]} print line[i]}}' "$src" > "$dest" ;;
  poisson) awk -F, -v OFS=, 'h==1 && n==0 {$8=0.7} h==1 {n++} $1=="id" {h=1} {print}' "$src" > "$dest" ;;
  modulus) awk -F, -v OFS=, 'h==1 && n==0 {$7="1e300"} h==1 {n++} $1=="id" {h=1} {print}' "$src" > "$dest" ;;
  tiny) awk -F, -v OFS=, 'h==1 && n==0 {$5="1e-300"} h==1 {n++} $1=="id" {h=1} {print}' "$src" > "$dest" ;;
  pressure) sed 's/^pressure\[Pa\],.*/pressure[Pa],1500/' "$src" > "$dest" ;;
  *) echo "unknown mode $mode" >&2; exit 64 ;;
esac
