#!/usr/bin/env bash
# Session 28's re-validation of the spot of the angle (src/discover/unexplained/spot.rs), from
# the root. BASE a build of bdcb9c3 (before the spot), NEW of this session's source, GEN the
# example beyond_library_cases. `validate.sh cases` makes the cases (session 27's sets: its
# validate.sh cases); `validate.sh diagnose BUILD NAME [SETS…]` diagnoses the sets given (all
# by default) and the real records with BUILD into $T/NAME, whole commands. The spot is offered
# only where the record's speed scale turns at most π/2 a sample (the slow records, --volts 2):
# on the 24-V sets NEW computes what BASE does. NOREAL=1 leaves the real records out.
set -e
T=${T:-/tmp/s28/v}
case $1 in
cases) bash papers/beyond-library/session27/validate.sh cases ;;
diagnose)
  BIN=$2; O=$T/$3; shift 3; mkdir -p $O
  SETS=${*:-h51 h68 h76 h77 h78 h82 h82v h83 h83v h84}
  for S in $SETS; do for C in $T/cases/$S/*/; do N=$(basename $C)
    $BIN diagnose --quiet --data $C/recording.csv --model $C/motor.toml --json $O/$N.json --out $O/$N.d > $O/$N.log 2>&1 || true
  done; done
  [ -n "$NOREAL" ] && { touch $O/DONE; exit 0; }
  for f in ../shared/data/real/hsm150/idf_*.csv; do n=$(basename $f .csv)
    $BIN diagnose --quiet --data $f --model examples/hsm150/model.toml --json $O/real-$n.json --out $O/real-$n.d > $O/real-$n.log 2>&1 || true
  done
  $BIN diagnose --quiet --data ../shared/data/real/emps/emps_estimation.csv --model examples/emps/model.toml --json $O/real-emps.json --out $O/real-emps.d > $O/real-emps.log 2>&1 || true
  touch $O/DONE
  ;;
esac
