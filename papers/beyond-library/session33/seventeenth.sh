#!/usr/bin/env bash
# Session 33: a seventeenth set of effects not built for (a battery's internal resistance behind
# the bridge, a Hall sensor's core compressing, a seal's drag thinning as the motor warms, the
# speed read on the load's side of a compliant coupling), made with the generator of its commit
# after the current's sign in what is read of I, the heat in what is read of omega and the drag
# growing with the heat were written (273bbd0), before any of them was diagnosed, to judge those
# blind. From the root, T=/tmp/s33/b:
#   seventeenth.sh cases | residual | diagnose BIN NAME   (session 31's new_set.sh)
T=${T:-/tmp/s33/b} HERE=papers/beyond-library/session33 SET=h94 SEED=940000 \
  EFFECTS=bus_sag,hall_compression,grease_thinning,load_side_encoder \
  exec bash papers/beyond-library/session31/new_set.sh "$@"
