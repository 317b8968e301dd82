#!/usr/bin/env bash
# Session 32: session 30's timing.sh (whole commands, quiet, one at a time, per case HEAD then
# NEW; each case's runtime_s), with HEAD a build of 4cb3aa1 and NEW one of c861b10, on the
# slowest five of c861b10's run and five cases the changes touch. From the root.
T=${T:-/tmp/s32/b} CASES="h68/resonant_sensor-680020 h68/eccentric-680008
  h76/bearing_defect-760002 h76/gear_ripple-760017 h93/current_deadband-930006
  h92/speed_clip-920010 h92/sensor_gain_heat-920007 h92/brush_bounce-920004
  h90/loose_part-900004 h68/sensor_heat_drift-680024" exec bash papers/beyond-library/session30/timing.sh
