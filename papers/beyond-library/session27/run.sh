#!/bin/sh
# Session 27 (2026-12-06): the three jitter rule breaks of session 26 read from the reports.
# BIN a build of e84a9b9 (discover's source as b6149e2's but for the Context's move), GEN its
# example beyond_library_cases.
set -e
BIN=${BIN:-motorcal}; GEN=${GEN:-beyond_library_cases}
HERE=$(cd "$(dirname "$0")" && pwd)
T=${T:-/tmp/s27}; mkdir -p $T/rf
$GEN --out $T/h84 --effects sample_jitter --per-effect 8 --seed-base 840000 > /dev/null
for N in 840001 840003 840006; do C=$T/h84/sample_jitter-$N
  $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $T/rf/$N.json --out $T/rf/$N.d > /dev/null 2>&1
done
python3 $HERE/jitter_lag.py $T/rf/840001.json $T/rf/840003.json $T/rf/840006.json > $HERE/jitter-lag-840000.txt
