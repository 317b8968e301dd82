#!/usr/bin/env bash
# Session 30: a thirteenth set of effects not built for (a bridge's dead time, a winding that
# warms, a tachometer read through a coupling capacitor, a loose part knocking), made with the
# generator of this session before any of them was diagnosed. From the root.
#   thirteenth.sh cases              makes them into $T/cases/h90
#   thirteenth.sh residual           what the library's best single term leaves (library-residual-900000.md)
#   thirteenth.sh diagnose BIN NAME  whole commands, two at a time, into $T/NAME and $T/tNAME/h90
set -e
T=${T:-/tmp/s30/b}; HERE=papers/beyond-library/session30
case $1 in
cases)
  target/release/examples/beyond_library_cases --out $T/cases/h90 \
    --effects dead_time,winding_heat,ac_coupled_tacho,loose_part --per-effect 4 --seed-base 900000
  ;;
residual)
  target/release/examples/library_residual $T/cases/h90/*/ > $HERE/library-residual-900000.md
  ;;
diagnose)
  BIN=$2; O=$T/$3; mkdir -p $O
  ls -d $T/cases/h90/*/ | xargs -P 2 -I{} bash -c 'C={}; N=$(basename $C); mkdir -p '$T'/t'$3'/h90/$N; /usr/bin/time -f "%e s" '$BIN' diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json '$O'/$N.json --out '$O'/$N.d > '$O'/$N.log 2>&1; ln -sfn '$O'/$N.json '$T'/t'$3'/h90/$N/report.json'
  ;;
esac
