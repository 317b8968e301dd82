#!/usr/bin/env bash
# Session 31: session 30's timing.sh (whole commands, quiet, one at a time, per case HEAD then
# NEW; each case's runtime_s), with HEAD a build of f9a1562 and NEW one of de8873c, on the
# slowest five of f9a1562's run and five cases the changes touch. From the root.
T=${T:-/tmp/s31/b} CASES="h76/bearing_defect-760002 h68/resonant_sensor-680020
  h76/gear_ripple-760017 h51/eccentric-510006 h68/eccentric-680008 h91/brake_release-910006
  h91/current_offset_step-910007 h68/flux_saturation-680011 h81/shorted_turn-810016
  h68/sensor_heat_drift-680024" exec bash papers/beyond-library/session30/timing.sh
