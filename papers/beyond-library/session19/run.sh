#!/usr/bin/env bash
# Session 19's runs, as they were made, from the root. BIN_base is a build of d118306 (session
# 18's last commit), BIN_new of this session's source (an overdamped coupling tried against the
# speed's reading of the current in its place); GEN the example beyond_library_cases of d268e97
# (the seventh set added); LIBRES the example library_residual; STUDY diagnose_study of BIN_new's
# source.
set -e
HERE=papers/beyond-library/session19; B=papers/beyond-library
# 1. The seventh set of effects not built for, made and diagnosed blind (whole commands, quiet,
#    the base first, then the new build).
$GEN --out /tmp/s19/hold/h78 --effects slew_limit,clutch_engagement,pwm_alias,speed_crosstalk,dc_link_resonance \
    --per-effect 4 --seed-base 780000 > $HERE/cases-780000.log
for BUILD in base:q78:r78 new:n78:rn78; do B_=${BUILD%%:*}; R=/tmp/s19/$(echo $BUILD | cut -d: -f2)
  TREE=/tmp/s19/${BUILD##*:}; eval BIN=\$BIN_$B_; mkdir -p $R
  for C in /tmp/s19/hold/h78/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
    mkdir -p $TREE/$N; ln -sf $R/$N.json $TREE/$N/report.json
  done
done
$LIBRES /tmp/s19/hold/h78/*/ > $HERE/library-residual-780000.md
T=/tmp/s19/hold/h78; L=$HERE/library-residual-780000.md
(cd $B && python3 kind_table.py $T:/tmp/s19/r78:session19/library-residual-780000.md) > $HERE/kind-table-780000.md
(cd $B && python3 rule_breaks.py $T:/tmp/s19/r78:session19/library-residual-780000.md) > $HERE/rule-breaks-780000-d118306.txt
(cd $B && python3 rule_breaks.py $T:/tmp/s19/rn78:session19/library-residual-780000.md) > $HERE/rule-breaks-780000-session19.txt
python3 $B/whole_commands.py /tmp/s19/q78 $T > $HERE/whole-command-times-780000-d118306-quiet.txt
python3 $B/whole_commands.py /tmp/s19/n78 $T > $HERE/whole-command-times-780000-session19-quiet.txt
python3 $B/session13/verdicts.py /tmp/s19/q78 /tmp/s19/n78 > $HERE/verdicts-780000-d118306-session19.txt
python3 $B/session12/compare_full.py /tmp/s19/q78 /tmp/s19/n78 > $HERE/compare-full-780000-d118306-session19.txt
python3 $HERE/case_table.py $T /tmp/s19/q78 > $HERE/case-table-780000-d118306.md
python3 $HERE/case_table.py $T /tmp/s19/n78 > $HERE/case-table-780000-session19.md
for n in 780004 780009 780014 780019; do
  grep -h '"truth"' $T/speed_crosstalk-$n/answer.json | sed "s/^/speed_crosstalk-$n: /"
done > $HERE/crosstalk-truths.txt
# 2. The crosstalk's law written by hand, as the model as given (before the change).
C=$T/speed_crosstalk-780004
$BIN_base diagnose --model $HERE/crosstalk-law-by-hand.toml --data $C/recording.csv --rank-only \
    --json /tmp/s19/xt.json > $HERE/crosstalk-law-by-hand.txt 2>&1
python3 -c "import json; e=json.load(open('/tmp/s19/xt.json'))['ranking'][0]; print(e['effect'], e['log_likelihood'], e['params'])" >> $HERE/crosstalk-law-by-hand.txt
grep "log likelihood" /tmp/s19/q78/speed_crosstalk-780004.log >> $HERE/crosstalk-law-by-hand.txt
# 3. No change where no coupling is damped past critical: the library's study and the coupling's.
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out /tmp/s19/study > $B/study-1100000-session19/log.txt
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out /tmp/s19/t13 > $B/terms-1300000-session19/log.txt
cp /tmp/s19/study/study.csv /tmp/s19/study/study.json $B/study-1100000-session19/
cp /tmp/s19/t13/study.csv /tmp/s19/t13/study.json $B/terms-1300000-session19/
python3 $B/compare_studies.py $B/study-1100000-session18/study.csv $B/study-1100000-session19/study.csv > $HERE/compare-study-1100000.txt
python3 $B/compare_studies.py $B/terms-1300000-session18/study.csv $B/terms-1300000-session19/study.csv > $HERE/compare-terms-1300000.txt
# 4. The 142 out-of-library cases of session 18 (its section 3 and 4 commands, into /tmp/s19/hold),
#    whole commands, quiet, the new build only; where the new step ran (its note), and the laws'
#    σ tables against session 18's (empty diffs: the same laws, σ to three digits).
S=/tmp/s19/hold; R=/tmp/s19/n142; mkdir -p $R
for C in $S/h51/*/ $S/h76/*/ $S/h77/*/ $S/h68/*/ $S/h69/*/ $S/h58/*/ $S/h63/*/ $S/h64/*/; do N=$(basename $C)
  $BIN_new diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log 2>&1
done
python3 $B/whole_commands.py $R $S/h51 $S/h76 $S/h77 > $HERE/whole-command-times-67-session19-quiet.txt
python3 $B/whole_commands.py $R $S/h68 $S/h69 $S/h58 $S/h63 $S/h64 > $HERE/whole-command-times-75-session19-quiet.txt
(for f in $R/*.log; do n=$(basename $f .log); grep -h "rings not" $f | sed "s/^/$n: /"; done) > $HERE/overdamped-notes-142.txt
for K in 67 75; do
  diff <(tail -n +3 $B/session18/whole-command-times-$K-session18-quiet.txt) <(tail -n +3 $HERE/whole-command-times-$K-session19-quiet.txt) > $HERE/laws-$K-session18-session19.diff || true
done
# 5. The three over 30 s, each with the base then the new build, in one run, quiet.
for c in h51/eccentric-510006 h76/gear_ripple-760017 h68/resonant_sensor-680020; do for B in base new; do
  N=$(basename $c); eval BIN=\$BIN_$B
  $BIN diagnose --quiet --data $S/$c/recording.csv --model $S/$c/motor.toml --json /tmp/s19/pair-$B-$N.json > /dev/null 2>&1
  python3 -c "import json; print('$N','$B', round(json.load(open('/tmp/s19/pair-$B-$N.json'))['runtime_s'],1))"
done; done > $HERE/budget-pair-3.txt
