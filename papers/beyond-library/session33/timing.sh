#!/usr/bin/env bash
# Session 33: session 30's timing.sh (whole commands, quiet, one at a time, per case HEAD then
# NEW; each case's runtime_s), with HEAD a build of c861b10 and NEW one of 273bbd0, on session
# 32's slowest three and five cases the changes touch. From the root.
T=${T:-/tmp/s33/b} CASES="h68/resonant_sensor-680020 h76/bearing_defect-760002
  h76/gear_ripple-760017 h93/current_deadband-930006 h93/bearing_heat_drag-930013
  h93/tacho_heat_offset-930003 h94/bus_sag-940005 h94/load_side_encoder-940012" \
  exec bash papers/beyond-library/session30/timing.sh
