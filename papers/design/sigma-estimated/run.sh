#!/bin/sh
# Session 27: the reported expected gap scored as `diagnose` scores, σ estimated per channel
# (`known_sigma_gap_nats` beside it: the same records at the σ given). Remakes the cases of
# "The cases" and "Designs on the concealed ties" and designs on them with the commands of
# those sections, the study's 20 records per truth on three of them (the realised lead beside
# the expected), then the current-driven loop (../current-driven/run.sh). BIN a build of the
# commit named in out.txt.
set -e
BIN=${BIN:-motorcal}
STUDY=${STUDY:-design_study}  # the example design_study, built with BIN
HERE=$(cd "$(dirname "$0")" && pwd)
W=${W:-/tmp/design-sigma}; rm -rf $W; mkdir -p $W; cd $W
L="U=±24,I=±300,omega=±3000"
run() { echo "\$ motorcal $*" | sed "s#$W/##g"; $BIN "$@" 2>&1 | sed "s#$W/##g"; }
quiet() { echo "\$ motorcal $* > /dev/null" | sed "s#$W/##g"; $BIN "$@" > /dev/null 2>&1; }
quiet simulate --effect coulomb_friction --magnitude 3 --input constant --seed 4 --out coulomb_m3
quiet diagnose --quiet --data coulomb_m3/recording.csv --model coulomb_m3/motor.toml --rank-only --json coulomb_m3/diag.json --out coulomb_m3/diagnosed
run design --model coulomb_m3/motor.toml --diagnosis coulomb_m3/diag.json --duration 0.5 --rate 1000 --limits $L --out coulomb_m3/design
for N in 1 8; do
  C=viscous_friction_$N
  quiet simulate --effect viscous_friction --conceal --input constant --seed $N --out $C
  quiet diagnose --quiet --data $C/recording.csv --model $C/motor.toml --rank-only --json $C/diag.json --out $C/diagnosed
  run design --model $C/motor.toml --diagnosis $C/diag.json --separate viscous_friction,quadratic_drag --duration 0.5 --rate 1000 --limits $L --out $C/design
done
run design --model viscous_friction_1/motor.toml --diagnosis viscous_friction_1/diag.json --separate viscous_friction,quadratic_drag --duration 0.5 --rate 1000 --limits $L --starts 16 --out viscous_friction_1/design16
for c in "coulomb_m3 load_torque,coulomb_friction" "viscous_friction_1 viscous_friction,quadratic_drag" "viscous_friction_8 viscous_friction,quadratic_drag"; do
  set -- $c
  echo "\$ cargo run --release --example design_study -- separate $1 $2 --records 20"
  $STUDY separate $1 $2 --records 20
done
echo "\$ ../current-driven/run.sh"
W=$W/current-driven sh $HERE/../current-driven/run.sh
