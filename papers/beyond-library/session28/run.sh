#!/usr/bin/env bash
# Session 28's tables, from the root, after `validate.sh diagnose` has run BASE and NEW into
# $T/base and $T/new (see validate.sh). Prints into this folder.
set -e
HERE=papers/beyond-library/session28; B=papers/beyond-library; T=${T:-/tmp/s28/v}
# The 24-V tenth and eleventh sets were run apart (base2, new2: validate.sh with NOREAL=1), and
# so was the twelfth set (base85, new85), made after the change:
#   beyond_library_cases --out $T/cases/h85v --effects encoder_missing_pulse --per-effect 8 \
#       --seed-base 850000 --volts 2
#   library_residual $T/cases/h85v/*/ > $HERE/library-residual-850000.md
for R in base new; do for f in $T/${R}2/*.json $T/${R}85/*.json; do ln -sf $f $T/$R/; done; done
python3 $B/session12/compare_full.py --ignore-units-of "omega*exp(-2*(1-cos(theta-theta_0))/w^2)" \
    $T/base $T/new > $HERE/compare-full-base-new.txt || true
python3 $B/session22/verdict_keys.py $T/base $T/new > $HERE/verdict-keys-base-new.txt || true
# Each set's reports as REPORTS/CASE/report.json, as kind_table.py and rule_breaks.py read them.
for R in base new; do for S in h77 h82 h82v h83 h83v h85v; do
  for C in $T/cases/$S/*/; do N=$(basename $C)
    [ -f $T/$R/$N.json ] || continue
    mkdir -p $T/t$R/$S/$N; ln -sf $T/$R/$N.json $T/t$R/$S/$N/report.json
  done
done; done
for R in base new; do
  (cd $B && python3 kind_table.py $T/cases/h83:$T/t$R/h83:session25/library-residual-830000.md \
      $T/cases/h83v:$T/t$R/h83v:session25/library-residual-830000.md) > $HERE/kind-table-830000-$R.md
  (cd $B && python3 rule_breaks.py $T/cases/h83:$T/t$R/h83:session25/library-residual-830000.md \
      $T/cases/h83v:$T/t$R/h83v:session25/library-residual-830000.md) > $HERE/rule-breaks-830000-$R.txt
  (cd $B && python3 kind_table.py $T/cases/h82:$T/t$R/h82:session23/library-residual-820000.md \
      $T/cases/h82v:$T/t$R/h82v:session23/library-residual-820000.md) > $HERE/kind-table-820000-$R.md
  (cd $B && python3 kind_table.py $T/cases/h77:$T/t$R/h77:session9/library-residual-770000.md) > $HERE/kind-table-770000-$R.md
  (cd $B && python3 kind_table.py $T/cases/h85v:$T/t$R/h85v:session28/library-residual-850000.md) > $HERE/kind-table-850000-$R.md
  (cd $B && python3 rule_breaks.py $T/cases/h85v:$T/t$R/h85v:session28/library-residual-850000.md) > $HERE/rule-breaks-850000-$R.txt
  python3 $B/whole_commands.py $T/$R $T/cases/h77 $T/cases/h82v $T/cases/h83v $T/cases/h85v > $HERE/whole-command-times-slow-$R.txt
done
