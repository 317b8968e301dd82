#!/usr/bin/env bash
# Session 31: a fifteenth set of effects not built for (a mass picked up at an instant, a speed
# sensor clipping at its range, a current sensor whose gain drifts with the heat, brushes bouncing), made with the
# generator of this session after the fade and the step were written (044521a, 41fc0c8), before any of them was diagnosed, to judge those blind. From the root.
#   fifteenth.sh cases              makes them into $T/cases/h92
#   fifteenth.sh residual           what the library's best single term leaves (library-residual-920000.md)
#   fifteenth.sh diagnose BIN NAME  whole commands, two at a time, into $T/NAME and $T/tNAME/h92
set -e
T=${T:-/tmp/s31/b}; HERE=papers/beyond-library/session31
case $1 in
cases)
  target/release/examples/beyond_library_cases --out $T/cases/h92 \
    --effects load_mass_change,speed_clip,sensor_gain_heat,brush_bounce --per-effect 4 --seed-base 920000
  ;;
residual)
  target/release/examples/library_residual $T/cases/h92/*/ > $HERE/library-residual-920000.md
  ;;
diagnose)
  BIN=$2; O=$T/$3; mkdir -p $O
  ls -d $T/cases/h92/*/ | xargs -P 2 -I{} bash -c 'C={}; N=$(basename $C); mkdir -p '$T'/t'$3'/h92/$N; /usr/bin/time -f "%e s" '$BIN' diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json '$O'/$N.json --out '$O'/$N.d > '$O'/$N.log 2>&1; ln -sfn '$O'/$N.json '$T'/t'$3'/h92/$N/report.json'
  ;;
esac
