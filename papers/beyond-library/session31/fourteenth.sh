#!/usr/bin/env bash
# Session 31: a fourteenth set of effects not built for (an arm lifted through a gearbox, a
# brake still releasing, a current sensor re-zeroing, a speed estimator switching its method), made with the
# generator of this session before any of them was diagnosed. From the root.
#   fourteenth.sh cases              makes them into $T/cases/h91
#   fourteenth.sh residual           what the library's best single term leaves (library-residual-910000.md)
#   fourteenth.sh diagnose BIN NAME  whole commands, two at a time, into $T/NAME and $T/tNAME/h91
set -e
T=${T:-/tmp/s31/b}; HERE=papers/beyond-library/session31
case $1 in
cases)
  target/release/examples/beyond_library_cases --out $T/cases/h91 \
    --effects gravity_arm,brake_release,current_offset_step,speed_range_switch --per-effect 4 --seed-base 910000
  ;;
residual)
  target/release/examples/library_residual $T/cases/h91/*/ > $HERE/library-residual-910000.md
  ;;
diagnose)
  BIN=$2; O=$T/$3; mkdir -p $O
  ls -d $T/cases/h91/*/ | xargs -P 2 -I{} bash -c 'C={}; N=$(basename $C); mkdir -p '$T'/t'$3'/h91/$N; /usr/bin/time -f "%e s" '$BIN' diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json '$O'/$N.json --out '$O'/$N.d > '$O'/$N.log 2>&1; ln -sfn '$O'/$N.json '$T'/t'$3'/h91/$N/report.json'
  ;;
esac
