#!/usr/bin/env bash
# Session 33: session 31's kind tables and rule breaks over every set of session33/sets.sh
# (the 254 cases and h94) in $T/tNAME, into kind-tables-NAME.md and rule-breaks-NAME.txt here.
# From the root:   T=/tmp/s33/b tables.sh NAME
set -e
T=${T:-/tmp/s33/b}; B=papers/beyond-library; HERE=$B/session33; NAME=$1
. $HERE/sets.sh
for p in $SETS; do
  S=${p%%:*}; L=${p##*:}
  [ -d $T/t$NAME/$S ] || continue
  echo "### $S"; (cd $B && python3 kind_table.py $T/cases/$S:$T/t$NAME/$S:$L)
done > $HERE/kind-tables-$NAME.md
args=""
for p in $SETS; do
  S=${p%%:*}; L=${p##*:}
  [ -d $T/t$NAME/$S ] && args="$args $T/cases/$S:$T/t$NAME/$S:$L"
done
(cd $B && python3 rule_breaks.py $args) > $HERE/rule-breaks-$NAME.txt
