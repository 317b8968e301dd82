#!/bin/sh
# Session 15's runs, as they were made, from the root. STUDY is the example diagnose_study of
# this session's build (the generator's oracle also on the noisy record), copied aside.
set -e
HERE=papers/beyond-library/session15; B=papers/beyond-library
# 1. The dynamic terms' studies, the seeds of sessions 5 and 14, then fresh seeds.
$STUDY --effects input_delay,sensor_lag,compliant_coupling --per-effect 10 --null 0 --two 0 --no-dev \
    --seed-base 1200000 --out /tmp/s15/t12 > $B/terms-1200000-session15/log.txt
$STUDY --effects compliant_coupling,sensor_lag --per-effect 20 --null 0 --two 0 --no-dev \
    --seed-base 1300000 --out /tmp/s15/t13 > $B/terms-1300000-session15/log.txt
$STUDY --effects compliant_coupling,sensor_lag,input_delay --per-effect 15 --null 0 --two 0 --no-dev \
    --seed-base 1500000 --out /tmp/s15/t15 > $B/terms-1500000-session15/log.txt
for S in 1200000:t12 1300000:t13 1500000:t15; do SEED=${S%%:*}; D=${S##*:}
  cp /tmp/s15/$D/study.csv /tmp/s15/$D/study.json $B/terms-$SEED-session15/
done
for SEED in 1200000 1300000; do
  python3 $B/compare_studies.py $B/terms-$SEED-session14/study.csv $B/terms-$SEED-session15/study.csv > $HERE/compare-terms-$SEED.txt
done
# 2. The library's study.
$STUDY --per-effect 5 --null 40 --two 20 --seed-base 1100000 --out /tmp/s15/study > $B/study-1100000-session15/log.txt
cp /tmp/s15/study/study.csv /tmp/s15/study/study.json $B/study-1100000-session15/
python3 $B/compare_studies.py $B/study-1100000-session14/study.csv $B/study-1100000-session15/study.csv > $HERE/compare-study-1100000.txt
# 3. Which cases the generator made differently from session 14's runs of the same seeds.
python3 $HERE/redrawn_cases.py \
  study-1100000 $B/study-1100000-session14/study.csv $B/study-1100000-session15/study.csv \
  terms-1200000 $B/terms-1200000-session14/study.csv $B/terms-1200000-session15/study.csv \
  terms-1300000 $B/terms-1300000-session14/study.csv $B/terms-1300000-session15/study.csv \
  > $HERE/redrawn-cases.txt
# 4. The three coupling misses' draws, traced: a temporary eprintln! in make_case printing the
#    redrawn draw's margins (not kept), `motorcal simulate --effect compliant_coupling --conceal
#    --seed S --input I` for 1300024 constant, 1300032 constant, 1200004 reversal:
#    redrawn-coupling-misses-trace.txt.
# 5. Not landed: the searched ripple offered to the naming (searched-ripple-not-landed.patch, on
#    06afe05), diagnose on tests/fixtures/beyond/bearing_defect-690003: searched-ripple-690003.txt.
