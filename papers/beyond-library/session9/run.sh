#!/bin/sh
# Session 9's runs, as they were made. BIN_OLD is a build of f9bfc1d, BIN_NEW of 50f436b;
# GEN and LIBRES the examples beyond_library_cases and library_residual of either build.
# Cases go to /tmp/hold (not kept in the repository: the generator remakes them).
set -e
HERE=$(dirname "$0"); B=$HERE/..
$GEN --out /tmp/hold/h76 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 \
    --seed-base 760000 > $HERE/cases-760000.log
$GEN --out /tmp/hold/h77 --effects gear_ripple,bearing_defect,eccentric,cogging --per-effect 5 \
    --seed-base 770000 --volts 2 > $HERE/cases-770000.log
# Whole commands, one at a time, the machine otherwise quiet; the new build first.
for BUILD in NEW OLD; do
  eval BIN=\$BIN_$BUILD; R=/tmp/s9/$BUILD; mkdir -p $R
  for C in /tmp/hold/h76/*/ /tmp/hold/h77/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $R/$N.json --out $R/$N.d > $R/$N.log
  done
  python3 $B/whole_commands.py $R /tmp/hold/h76 /tmp/hold/h77
  # kind_table.py and rule_breaks.py read REPORTS/CASE/report.json.
  for C in /tmp/hold/h76/* /tmp/hold/h77/*; do N=$(basename $C); mkdir -p $R-kt/$N; ln -sf $R/$N.json $R-kt/$N/report.json; done
done
$LIBRES /tmp/hold/h76/*/ > $HERE/library-residual-760000.md
$LIBRES /tmp/hold/h77/*/ > $HERE/library-residual-770000.md
for BUILD in OLD NEW; do
  python3 $B/kind_table.py /tmp/hold/h76:/tmp/s9/$BUILD-kt:$HERE/library-residual-760000.md \
      /tmp/hold/h77:/tmp/s9/$BUILD-kt:$HERE/library-residual-770000.md
  python3 $B/rule_breaks.py /tmp/hold/h76:/tmp/s9/$BUILD-kt:$HERE/library-residual-760000.md \
      /tmp/hold/h77:/tmp/s9/$BUILD-kt:$HERE/library-residual-770000.md
done
# The laws against the truths' orders, over these and session 7–8's angle cases (g72, g73:
# `--effects gear_ripple --per-effect 4 --seed-base 720000 | 730000 --volts 2`; h74, h75:
# session 8's), reports of both builds gathered in one folder each.
python3 $HERE/angle_laws.py /tmp/sets/g72,/tmp/sets/g73,/tmp/hold/h74,/tmp/hold/h75,/tmp/hold/h76,/tmp/hold/h77 \
    /tmp/s9/OLD,/tmp/s9/NEW
# The rise of a ripple law at chosen orders, through the ODE.
MOTORCAL=$BIN_NEW $HERE/fits_by_order.sh /tmp/sets/g72/gear_ripple-720004 0.5335 0.467 0.371 0.057
MOTORCAL=$BIN_NEW $HERE/fits_by_order.sh /tmp/hold/h74/gear_ripple-740027 0.5512 0.558 0.101
MOTORCAL=$BIN_NEW $HERE/fits_by_order.sh /tmp/hold/h76/gear_ripple-760001 0.7623 0.726
MOTORCAL=$BIN_NEW $HERE/fits_by_order.sh /tmp/hold/h77/gear_ripple-770017 0.2149 0.220
MOTORCAL=$BIN_NEW $HERE/fits_by_order.sh /tmp/hold/h77/cogging-770008 12 10.56
