#!/usr/bin/env bash
# Session 31: rule_breaks.py over every set of sets.sh in $T/tNAME, into rule-breaks-NAME.txt.
# From the root.
set -e
T=${T:-/tmp/s31/b}; B=papers/beyond-library; NAME=$1
. $B/session31/sets.sh
args=""
for p in $SETS; do S=${p%%:*}; L=${p##*:}; args="$args $T/cases/$S:$T/t$NAME/$S:$L"; done
(cd $B && python3 rule_breaks.py $args) > $B/session31/rule-breaks-$NAME.txt
