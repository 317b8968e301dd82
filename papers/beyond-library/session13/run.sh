#!/bin/sh
# Session 13's runs, as they were made. BIN_s13 is a build of 4c6f13f (session 12's diagnose,
# simulate's record making moved into the library), BIN_shape of 6377d0a (the law's shape
# search also stops on the score's bound). The cases are session 9's, remade by its run.sh
# (beyond_library_cases, seeds 760000 and 770000 --volts 2) into /tmp/hold/h76 and h77.
set -e
HERE=$(dirname "$0"); B=$HERE/..
# Quiet timing, nothing else running: per case the new build, then the old.
for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
  for BUILD in shape s13; do eval BIN=\$BIN_$BUILD; R=/tmp/s13/q-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
python3 $B/whole_commands.py /tmp/s13/q-s13 /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-4c6f13f-quiet.txt
python3 $B/whole_commands.py /tmp/s13/q-shape /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-6377d0a-quiet.txt
python3 $B/session12/compare_full.py /tmp/s13/q-s13 /tmp/s13/q-shape > $HERE/compare-full-40-4c6f13f-6377d0a-quiet.txt
python3 $HERE/verdicts.py /tmp/s13/q-s13 /tmp/s13/q-shape > $HERE/verdicts-40-4c6f13f-6377d0a.txt
# The slowest case twice more with each build, alternating (its spread between runs).
C=/tmp/hold/h76/bearing_defect-760018
for BUILD in shape s13 shape s13; do eval BIN=\$BIN_$BUILD
  $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json /tmp/s13/b18.json --out /tmp/s13/b18.d > /dev/null 2>&1
  python3 -c "import json; r=json.load(open('/tmp/s13/b18.json')); print('$BUILD', round(r['runtime_s'], 1), 's; ranking', round(r['ranking_s'], 1), 's; selection', round(r['selection_s'], 1), 's')"
done > $HERE/bearing_defect-760018-repeats.txt
# One fit per rayon job (`.with_max_len(1)` on the selection's, the named laws' and the pruning's
# fits; BIN_jobs a build of 6377d0a with that change, not kept), on the ten slowest cases of the
# run above, per case that build then 6377d0a.
for N in bearing_defect-760018 gear_ripple-760017 eccentric-760003 bearing_defect-760002 gear_ripple-760013 cogging-760008 eccentric-760019 cogging-770012 cogging-770008 cogging-770004; do
  C=/tmp/hold/h76/$N; [ -d $C ] || C=/tmp/hold/h77/$N
  for BUILD in jobs shape; do eval BIN=\$BIN_$BUILD; R=/tmp/s13/t10-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
python3 $HERE/verdicts.py /tmp/s13/t10-shape /tmp/s13/t10-jobs > $HERE/one-fit-per-job-10-slowest.txt
python3 $B/session12/compare_full.py /tmp/s13/t10-shape /tmp/s13/t10-jobs | tail -1 >> $HERE/one-fit-per-job-10-slowest.txt
