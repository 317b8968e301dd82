#!/usr/bin/env bash
# Session 32: a sixteenth set of effects not built for (a bearing whose drag grows with the
# heat, a current sensor's dead band, a tachometer's zero drifting with the heat, the current
# sampled ahead of the speed), made with the generator of its commit after the heat and the
# speed's range in what is read (dd32d3f) and the supply's knocks (c861b10) were written, before
# any of them was diagnosed, to judge those blind. From the root, T=/tmp/s32/b:
#   sixteenth.sh cases | residual | diagnose BIN NAME   (session 31's new_set.sh)
T=${T:-/tmp/s32/b} HERE=papers/beyond-library/session32 SET=h93 SEED=930000 \
  EFFECTS=bearing_heat_drag,current_deadband,tacho_heat_offset,current_skew \
  exec bash papers/beyond-library/session31/new_set.sh "$@"
