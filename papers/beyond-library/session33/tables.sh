#!/usr/bin/env bash
# Session 33: session 32's tables.sh over the sets of session33/sets.sh (the 254 cases and h94)
# in $T/tNAME, into kind-tables-NAME.md and rule-breaks-NAME.txt here. From the root:
#   T=/tmp/s33/b tables.sh NAME
T=${T:-/tmp/s33/b} HERE=papers/beyond-library/session33 \
  exec bash papers/beyond-library/session32/tables.sh "$@"
