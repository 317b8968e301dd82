#!/usr/bin/env bash
# Session 31: a fourteenth set of effects not built for (an arm lifted through a gearbox, a
# brake still releasing, a current sensor re-zeroing, a speed estimator switching its method),
# made with the generator of ac2916a before any of them was diagnosed. From the root:
#   fourteenth.sh cases | residual | diagnose BIN NAME   (new_set.sh)
SET=h91 SEED=910000 EFFECTS=gravity_arm,brake_release,current_offset_step,speed_range_switch \
  exec bash papers/beyond-library/session31/new_set.sh "$@"
