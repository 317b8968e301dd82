#!/usr/bin/env bash
# Session 31: a fifteenth set of effects not built for (a mass picked up at an instant, a speed
# sensor clipping at its range, a current sensor whose gain drifts with the heat, brushes
# bouncing), made with the generator of ce695b1 after the fade and the step were written
# (044521a, 41fc0c8), before any of them was diagnosed, to judge those blind. From the root:
#   fifteenth.sh cases | residual | diagnose BIN NAME   (new_set.sh)
SET=h92 SEED=920000 EFFECTS=load_mass_change,speed_clip,sensor_gain_heat,brush_bounce \
  exec bash papers/beyond-library/session31/new_set.sh "$@"
