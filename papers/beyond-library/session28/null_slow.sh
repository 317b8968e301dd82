#!/usr/bin/env bash
# Null records at 2 V, where the spot is offered (the crate's null studies are at 24 V, where it
# is not): `simulate` with the nominal model as the truth (the eleventh set's slow motor.toml,
# U = 2 V), seeds 2400001–2400100, the constant, step, reversal and square inputs in turn, each
# diagnosed rank-only (ranking, selection and the verdict) by BASE and NEW. From the root.
set -e
T=${T:-/tmp/s28/null2v}; BASE=${BASE:-/tmp/s28/bin/motorcal-base}; NEW=${NEW:-/tmp/s28/bin/motorcal-final}
INPUTS=(constant step reversal square)
for i in $(seq 1 100); do S=$((2400000 + i)); C=$T/null-$S
  $NEW simulate --truth $T/motor2v.toml --nominal $T/motor2v.toml --input ${INPUTS[$((i % 4))]} --seed $S --out $C > /dev/null
  for B in BASE NEW; do BIN=${!B}
    $BIN diagnose --quiet --rank-only --data $C/recording.csv --model $C/motor.toml --json $C/$B.json > /dev/null 2>&1 || echo "$S $B failed"
  done
done
python3 - "$T" <<'PY'
import json, glob, sys
for b in ("BASE", "NEW"):
    sel = ver = either = 0; n = 0; alarms = []
    for f in sorted(glob.glob(f"{sys.argv[1]}/null-*/{b}.json")):
        r = json.load(open(f)); n += 1
        s = r["selected"] not in (None, "none"); u = r.get("unexplained") is not None
        sel += s; ver += u; either += s or u
        if s or u:
            alarms.append((f.split("/")[-2], r["selected"], u and r["unexplained"]["fingerprint"]["kind"]))
    print(f"{b}: {n} null records at 2 V: selection {sel}, verdict {ver}, either {either}")
    for a in alarms:
        print("  ", *a)
PY
