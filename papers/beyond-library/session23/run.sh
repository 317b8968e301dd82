#!/usr/bin/env bash
# Sessions 23–24's runs, as they were made (scratch in /tmp/s23). GEN the example
# beyond_library_cases of 6d0fc21 (the tenth set added); LIBRES the example library_residual;
# BIN_base a build of 6d0fc21, BIN_new of session 23's source (a contaminated normal that is no
# set of isolated outliers reported as a noise of two scales: src/discover/unexplained/
# outliers.rs, generic.rs); STUDY diagnose_study of BIN_new's source. Session 23's own runs of
# these were lost with its scratch; sections 1–3 were remade in session 24, and section 4 (its
# cases remade by session 20's run.sh, section 1) in session 25, whose scratch had lost them again.
set -e
HERE=papers/beyond-library/session23; B=papers/beyond-library; S=/tmp/s23
# 1. The tenth set, made (the magnet's pickup on slow records), then diagnosed blind by the
#    base (whole commands, one at a time, quiet), then by the new build.
$GEN --out $S/h82 --effects emi_bursts,supply_dips,seal_friction,sensor_hysteresis \
    --per-effect 4 --seed-base 820000 > $HERE/cases-820000.log
$GEN --out $S/h82v --effects magnet_pickup --per-effect 4 --seed-base 825000 --volts 2 \
    > $HERE/cases-825000.log
mkdir -p $S/all82; for d in $S/h82/* $S/h82v/*; do ln -sfn $d $S/all82/$(basename $d); done
$LIBRES $S/all82/*/ > $HERE/library-residual-820000.md
blind() { # CASES BIN REPORTS TREE
  mkdir -p $3 $4
  for C in $1/*/; do N=$(basename $C)
    $2 diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $3/$N.json --out $3/$N.d > $3/$N.log 2>&1
    mkdir -p $4/$N; ln -sf $3/$N.json $4/$N/report.json
  done
}
blind $S/all82 $BIN_base $S/r82 $S/t82
blind $S/all82 $BIN_new $S/n82 $S/tn82
cp $S/n82/emi_bursts-820009.d/unexplained.png $B/emi_bursts-820009-unexplained.png
for T in t82:6d0fc21 tn82:session23; do
  (cd $B && python3 kind_table.py $S/all82:$S/${T%%:*}:session23/library-residual-820000.md) > $HERE/kind-table-820000-${T##*:}.md
  (cd $B && python3 rule_breaks.py $S/all82:$S/${T%%:*}:session23/library-residual-820000.md) > $HERE/rule-breaks-820000-${T##*:}.txt
done
python3 $B/session19/case_table.py $S/all82 $S/r82 > $HERE/case-table-820000-6d0fc21.md
python3 $B/session19/case_table.py $S/all82 $S/n82 > $HERE/case-table-820000-session23.md
python3 $B/whole_commands.py $S/r82 $S/all82 > $HERE/whole-command-times-820000-6d0fc21.txt
python3 $B/whole_commands.py $S/n82 $S/all82 > $HERE/whole-command-times-820000-session23.txt
python3 $B/session22/verdict_keys.py $S/r82 $S/n82 > $HERE/verdict-keys-820000-6d0fc21-session23.txt
# 2. What a contaminated normal can gain on bursts at 2 σ and at 4.8 σ, knowing nothing of
#    where they fall.
(cd $HERE && python3 oracle_bursts.py > oracle-bursts.txt)
# 3. The coupling's and the lag's concealed cases, the library's study, 100 fresh nulls, with
#    the new build; against session 22's.
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out $S/t13 > $B/terms-1300000-session23/log.txt
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out $S/study > $B/study-1100000-session23/log.txt
$STUDY --per-effect 0 --null 100 --two 0 --no-dev --seed-base 1900000 --out $S/null19 > $B/null-1900000-session23/log.txt
for D in t13:terms-1300000 study:study-1100000 null19:null-1900000; do
  cp $S/${D%%:*}/study.csv $S/${D%%:*}/study.json $B/${D##*:}-session23/
done
python3 $B/compare_studies.py $B/study-1100000-session22/study.csv $B/study-1100000-session23/study.csv > $HERE/compare-study-1100000.txt
python3 $B/compare_studies.py $B/terms-1300000-session22/study.csv $B/terms-1300000-session23/study.csv > $HERE/compare-terms-1300000.txt
# 4. The 118 out-of-library cases of session 20 (its run.sh, section 1, into $S/hold), per case
#    the base then the new build, quiet; then the real records, rank-only, the new build then
#    the base.
mkdir -p $S/b118 $S/n118
for C in $S/hold/h78/*/ $S/hold/h51/*/ $S/hold/h68/*/ $S/hold/h76/*/ $S/hold/h77/*/; do N=$(basename $C)
  $BIN_base diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $S/b118/$N.json --out $S/b118/$N.d > $S/b118/$N.log 2>&1
  $BIN_new diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $S/n118/$N.json --out $S/n118/$N.d > $S/n118/$N.log 2>&1
done
python3 $B/session22/verdict_keys.py $S/b118 $S/n118 > $HERE/verdict-keys-118-6d0fc21-session23.txt
python3 $B/session12/compare_full.py $S/b118 $S/n118 > $HERE/compare-full-118-6d0fc21-session23.txt
python3 $B/whole_commands.py $S/n118 $S/hold/h78 $S/hold/h51 $S/hold/h68 $S/hold/h76 $S/hold/h77 > $HERE/whole-command-times-118-session23.txt
python3 $B/whole_commands.py $S/b118 $S/hold/h78 $S/hold/h51 $S/hold/h68 $S/hold/h76 $S/hold/h77 > $HERE/whole-command-times-118-6d0fc21.txt
for V in new base; do eval BIN=\$BIN_$V; mkdir -p $S/real/$V
  for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
    $BIN diagnose --quiet --rank-only --data $f --model examples/hsm150/model.toml --json $S/real/$V/$n.json > /dev/null 2>&1
  done
  $BIN diagnose --quiet --rank-only --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $S/real/$V/emps.json > /dev/null 2>&1
done
python3 $HERE/../session22/verdict_keys.py $S/real/base $S/real/new > $HERE/verdict-keys-real-6d0fc21-session23.txt
python3 $B/session12/compare_full.py $S/real/base $S/real/new > $HERE/compare-full-real-6d0fc21-session23.txt
# 5. What led emi_bursts-820001's verdict with each build (printed in the section, not kept).
C=$S/h82/emi_bursts-820001
for V in base new; do eval BIN=\$BIN_$V
  $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $S/e1-$V.json > /dev/null 2>&1
  python3 -c "import json; u=json.load(open('$S/e1-$V.json'))['unexplained']; print('$V', round(u['evidence'],1), u['suggestion'][:120])"
done
