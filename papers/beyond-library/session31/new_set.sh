#!/usr/bin/env bash
# Session 31: a set of effects not built for, made with the generator of its commit and
# diagnosed, for fourteenth.sh and fifteenth.sh (and session 30's thirteenth.sh's shape). From
# the root, with SET (h91), SEED (910000) and EFFECTS (a,b,…) set by the caller.
#   cases              makes them into $T/cases/$SET
#   residual           what the library's best single term leaves (library-residual-$SEED.md)
#   diagnose BIN NAME  whole commands, two at a time, into $T/NAME and $T/tNAME/$SET
set -e
T=${T:-/tmp/s31/b}; HERE=${HERE:-papers/beyond-library/session31}
case $1 in
cases)
  target/release/examples/beyond_library_cases --out $T/cases/$SET \
    --effects $EFFECTS --per-effect 4 --seed-base $SEED
  ;;
residual)
  target/release/examples/library_residual $T/cases/$SET/*/ > $HERE/library-residual-$SEED.md
  ;;
diagnose)
  BIN=$2; O=$T/$3; mkdir -p $O
  export T BIN O SET NAME=$3
  ls -d $T/cases/$SET/*/ | xargs -P 2 -I{} bash -c 'C={}; N=$(basename $C); mkdir -p $T/t$NAME/$SET/$N
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $O/$N.json --out $O/$N.d > $O/$N.log 2>&1
    ln -sfn $O/$N.json $T/t$NAME/$SET/$N/report.json'
  ;;
esac
