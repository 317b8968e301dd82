#!/usr/bin/env bash
# Session 32: session 31's kind tables and rule breaks over every set of session32/sets.sh
# (the 238 cases and h93) in $T/tNAME, into kind-tables-NAME.md and rule-breaks-NAME.txt here.
# From the root:   T=/tmp/s32/b tables.sh NAME   (HERE, another session's folder with its own sets.sh)
set -e
T=${T:-/tmp/s32/b}; B=papers/beyond-library; HERE=${HERE:-$B/session32}; NAME=$1
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
