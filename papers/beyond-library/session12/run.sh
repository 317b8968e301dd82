#!/bin/sh
# Session 12's runs, as they were made. BIN_base12 is a build of 1c0c09d (session 11's source),
# BIN_once of 5ecd29f (6c876a4: NUTS tries the Laplace metric first above k̂ 0.7; 5ecd29f: a law
# named by both the verdict and the model as given is fitted once), BIN_s12 of d252d3d (5ecd29f
# with the current-driven design merged: diagnose's code is 5ecd29f's). The cases are session
# 9's, remade by its run.sh (beyond_library_cases, seeds 760000 and 770000 --volts 2) into
# /tmp/hold/h76 and h77.
set -e
HERE=$(dirname "$0"); B=$HERE/..
# 1. The new build on the 40 cases while a helper built and tested beside it (loaded: its
#    times are no budget figures); its reports against session 11's quiet ones of 863f82b.
R=/tmp/s12/once; mkdir -p $R
for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
  $BIN_once diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
done
python3 $HERE/compare_full.py /tmp/s11/q-whole /tmp/s12/once > $HERE/compare-full-40-863f82b-5ecd29f.txt
# 2. Quiet timing, nothing else running: per case the new build, then the old.
for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
  for BUILD in s12 base12; do eval BIN=\$BIN_$BUILD; R=/tmp/s12/q-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
for BUILD in base12 s12; do
  [ $BUILD = base12 ] && NAME=1c0c09d || NAME=d252d3d
  python3 $B/whole_commands.py /tmp/s12/q-$BUILD /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-$NAME-quiet.txt
done
python3 $HERE/compare_full.py /tmp/s12/q-base12 /tmp/s12/q-s12 > $HERE/compare-full-40-1c0c09d-d252d3d-quiet.txt
python3 $HERE/fallbacks.py /tmp/s12/q-base12 /tmp/s12/q-s12 > $HERE/fallbacks-40-1c0c09d-d252d3d-quiet.txt
# 3. The fit that fell back, alone: cogging-770004's BM2 fit after its law, the law held at its
#    estimates (the amended model.toml with the law's coefficients taken out of [calibrate]),
#    by NUTS on either metric, 4 × 500 draws.
C=/tmp/hold/h77/cogging-770004
sed '/^"law\./d' /tmp/s12/q-s12/cogging-770004.d/model.toml > /tmp/s12/held.toml
for M in laplace windows; do
  $BIN_s12 fit --quiet --data $C/recording.csv --model /tmp/s12/held.toml --bm 2 --sampler nuts-dense \
      --metric-adaptation $M --draws 500 --out /tmp/s12/nuts-$M > /tmp/s12/nuts-$M.log 2>&1
  head -6 /tmp/s12/nuts-$M.log
done > $HERE/fit-after-bm2-cogging-770004-metrics.txt
python3 -c "
import json;d=json.load(open('/tmp/s12/nuts-laplace/fit.json'));m=d['map'][0];print(f\"fit.json: MAP {m['name']} = {m['value']:.4f}, its Laplace sd {m['laplace_sd']:.4f}\")" >> $HERE/fit-after-bm2-cogging-770004-metrics.txt
