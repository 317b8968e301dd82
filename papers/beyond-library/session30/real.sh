#!/usr/bin/env bash
# Session 30: session 29's real.sh (the real records, whole commands, one at a time, by HEAD then
# REV), run with HEAD a build of 893cc94 and REV one of 438186c, into /tmp/s30/real. From the root.
T=${T:-/tmp/s30/real} exec bash papers/beyond-library/session29/real.sh
