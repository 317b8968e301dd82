#!/usr/bin/env bash
# Session 32: session 29's real.sh (the real records, whole commands, one at a time, by HEAD then
# REV), run with HEAD a build of 4cb3aa1 and REV one of c861b10, into /tmp/s32/real; compared
# by session12/compare_full.py. From the root.
T=${T:-/tmp/s32/real} exec bash papers/beyond-library/session29/real.sh
