#!/bin/sh
# Session 11's runs, as they were made (the runs are named phase and whole). BIN_phase is a build of 595d721 (session 10's kept
# science), BIN_whole of 863f82b (the order's peak a quarter spacing from a whole order, and the
# law also fitted at that whole order), BIN_QUARTER of 78271af (session 10's reverted quarter rule);
# STUDY the example diagnose_study of 863f82b. The cases
# are session 9's, remade by its run.sh (beyond_library_cases, seeds 760000 and 770000 --volts 2)
# into /tmp/hold/h76 and h77.
set -e
HERE=$(dirname "$0"); B=$HERE/..
# 1. Both builds on the 40 cases while the clean-clone CI and the study used the machine
#    (whole-command-times-*-loaded.txt: their times are not budget figures).
for BUILD in whole phase; do
  eval BIN=\$BIN_$BUILD; R=/tmp/s11/$BUILD; mkdir -p $R
  for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
  for C in /tmp/hold/h76/* /tmp/hold/h77/*; do N=$(basename $C); S=$(basename $(dirname $C))
    mkdir -p $R-kt/$N $R-cmp/$S/$N; ln -sf $R/$N.json $R-kt/$N/report.json; ln -sf $R/$N.json $R-cmp/$S/$N/report.json
  done
done
python3 $B/compare_reports.py /tmp/s11/phase-cmp /tmp/s11/whole-cmp > $HERE/compare-40-595d721-863f82b.txt
python3 $B/session9/angle_laws.py /tmp/hold/h76,/tmp/hold/h77 /tmp/s11/phase,/tmp/s11/whole > $HERE/angle-laws-595d721-863f82b.md
for BUILD in phase whole; do
  [ $BUILD = phase ] && NAME=595d721 || NAME=863f82b
  python3 $B/kind_table.py /tmp/hold/h76:/tmp/s11/$BUILD-kt:$B/session9/library-residual-760000.md \
      /tmp/hold/h77:/tmp/s11/$BUILD-kt:$B/session9/library-residual-770000.md > $HERE/kind-table-760000-$NAME.md
  python3 $B/rule_breaks.py /tmp/hold/h76:/tmp/s11/$BUILD-kt:$B/session9/library-residual-760000.md \
      /tmp/hold/h77:/tmp/s11/$BUILD-kt:$B/session9/library-residual-770000.md > $HERE/rule-breaks-760000-$NAME.txt
  python3 $B/whole_commands.py /tmp/s11/$BUILD /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-$NAME-loaded.txt
done
# 2. The library's study with the new build (run from the repository's root).
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out /tmp/s11/study > $B/study-1100000-session11/log.txt
python3 $B/compare_studies.py $B/study-1100000-session9/study.csv /tmp/s11/study/study.csv > $HERE/compare-study-1100000.txt
# 3. The three fixtures by each build (78271af: the reverted quarter rule of session 10).
BINS="595d721=$BIN_phase 78271af=$BIN_QUARTER 863f82b=$BIN_whole" $HERE/fixtures.sh > $HERE/fixtures-595d721-78271af-863f82b.txt
# 4. Quiet timing, nothing else running: per case the new build, then the old.
for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
  for BUILD in whole phase; do eval BIN=\$BIN_$BUILD; R=/tmp/s11/q-$BUILD; mkdir -p $R
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
  done
done
for BUILD in phase whole; do
  [ $BUILD = phase ] && NAME=595d721 || NAME=863f82b
  python3 $B/whole_commands.py /tmp/s11/q-$BUILD /tmp/hold/h76 /tmp/hold/h77 > $HERE/whole-command-times-760000-$NAME-quiet.txt
done
# The quiet runs' reports against the loaded runs', build by build (REPORTS/SET/CASE/report.json
# links made as in 1.).
python3 $B/compare_reports.py /tmp/s11/whole-cmp /tmp/s11/qcmp/whole > $HERE/compare-40-863f82b-loaded-quiet.txt
python3 $B/compare_reports.py /tmp/s11/phase-cmp /tmp/s11/qcmp/phase > $HERE/compare-40-595d721-loaded-quiet.txt
