#!/usr/bin/env bash
# Session 31: session 29's real.sh (the real records, whole commands, one at a time, by HEAD then
# REV), run with HEAD a build of f9a1562 and REV one of de8873c, into /tmp/s31/real. From the root.
T=${T:-/tmp/s31/real} exec bash papers/beyond-library/session29/real.sh
