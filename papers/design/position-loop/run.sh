#!/bin/sh
# Session 16: `motorcal design` on a position_loop (EMPS's cascade on the fixture
# tests/fixtures/design/position_loop.toml). A record that never reverses (the reference ramps
# at 0.1 m/s for 1 s; the truth a 3-N Coulomb friction under σ = SQ on q and 5 N on the force)
# makes the Coulomb/load tie; `design --diagnosis` designs the reference's speed in 8 segments
# over 1 s at 1 kHz, once with the force held to force=±300 and once with the default force
# limit, the ±351.5-N saturation (before the default, SQ=1e-5 and no force limit: out-10um.txt,
# whose second case is the saturating one); each candidate as the truth at its estimate is then simulated
# on the designed reference (20 seeds, 1001-1020) and ranked by `diagnose --rank-only` over the
# whole library. Last, `design --pin J,d` at the model's values. BIN is a build of the commit
# named in papers/design.md; W a scratch folder.
set -e
BIN=${BIN:-motorcal}
HERE=$(cd "$(dirname "$0")" && pwd); ROOT=$HERE/../../..
FIX=$ROOT/tests/fixtures/design/position_loop.toml
W=${W:-/tmp/design-position}
# σ of q [m]; the force's is 5 N. EMPS's after its fit: 1.8 µm and 3.0 N.
SQ=${SQ:-2e-6}
rm -rf $W; mkdir -p $W
truth() { # truth NAME J d TERMS > file: the fixture with J, d and TERMS
  python3 - "$FIX" "$2" "$3" "$4" <<'PY'
import sys
fixture, j, d, terms = sys.argv[1:]
section = ""
for line in open(fixture).read().splitlines():
    if line.startswith("["): section = line
    if section == "[motor]" and line.startswith("J = "): line = f"J = {j}"
    if section == "[motor]" and line.startswith("d = "): line = f"d = {d}"
    if line == "[drive]": print(terms.replace("\\n", "\n"))
    print(line)
PY
}
python3 -c "
print('t,q_ref')
for i in range(1, 1001): print(f'{i/1000},{0.1*i/1000}')" > $W/ramp.csv
truth coulomb 95.2 205.0 '[terms.coulomb_friction]\nT_c = 3.0\nomega_s = 0.005\n' > $W/coulomb.toml
echo "== the tie: simulate on the ramp, diagnose"
$BIN simulate --truth $W/coulomb.toml --nominal $FIX --input $W/ramp.csv --noise-sd $SQ 5 \
    --seed 3 --out $W/ramp
$BIN diagnose --rank-only --data $W/ramp/recording.csv --model $FIX --json $W/ramp/diag.json \
    --out $W/ramp/diag
for CASE in held:q=±0.1,omega=±0.5,force=±300 default:q=±0.1,omega=±0.5; do
  NAME=${CASE%%:*}; LIMITS=${CASE#*:}; D=$W/$NAME
  echo "== design ($NAME, --limits $LIMITS)"
  /usr/bin/time -f "design wall %e s" $BIN design --model $FIX --diagnosis $W/ramp/diag.json \
      --duration 1 --rate 1000 --limits $LIMITS --noise-sd $SQ 5 --out $D/design
  for T in coulomb_friction load_torque; do
    python3 - $D/design/design.json $T > $D/$T.args <<'PY'
import json, sys
v = json.load(open(sys.argv[1]))["candidates_at"]["values"][sys.argv[2]]
extra = "omega_s = 0.005\\n" if sys.argv[2] == "coulomb_friction" else ""
term = "\\n".join(f"{k.split('.', 1)[1]} = {x!r}" for k, x in v.items() if "." in k)
print(v["J"], v["d"], f"[terms.{sys.argv[2]}]\\n{term}\\n{extra}")
PY
    truth $T $(cut -d' ' -f1 $D/$T.args) $(cut -d' ' -f2 $D/$T.args) "$(cut -d' ' -f3- $D/$T.args)" > $D/$T.toml
    for SEED in $(seq 1001 1020); do
      R=$D/records/$T/$SEED
      $BIN simulate --truth $D/$T.toml --nominal $FIX --input $D/design/input.csv \
          --noise-sd $SQ 5 --seed $SEED --out $R > /dev/null
      $BIN diagnose --quiet --rank-only --data $R/recording.csv --model $FIX \
          --json $R/whole.json --out $R/whole > /dev/null
    done
  done
done
echo "== pin J,d at the model's values"
$BIN design --model $FIX --pin J,d --duration 1 --rate 1000 --limits q=±0.1,omega=±0.5,force=±300 \
    --noise-sd $SQ 5 --out $W/pin
python3 - "$W" <<'PY'
import json, sys, glob
w = sys.argv[1]
print()
print("| limits | truth | designed gap | reversal | step | whole library names the truth (of 20) | its selections |")
print("|---|---|---|---|---|---|---|")
for name in ("held", "default"):
    d = json.load(open(f"{w}/{name}/design/design.json"))
    fixed = {f["input"]: f for f in d["fixed_experiments"]}
    fmt = lambda f: f"{f['expected_gap_nats']:.2f} ± {f['expected_gap_sd_nats']:.2f}" + ("" if f["within_limits"] else " (passes)")
    for t in ("coulomb_friction", "load_torque"):
        picks = {}
        for p in sorted(glob.glob(f"{w}/{name}/records/{t}/*/whole.json")):
            s = json.load(open(p))["selected"]
            picks[s] = picks.get(s, 0) + 1
        print(f"| {d['limits']} | {t} | {d['expected_gap_nats']:.2f} ± {d['expected_gap_sd_nats']:.2f} | "
              f"{fmt(fixed['reversal'])} | {fmt(fixed['step'])} | {picks.get(t, 0)} | "
              + ", ".join(f"{k} {v}" for k, v in sorted(picks.items(), key=lambda kv: -kv[1])) + " |")
    print(f"peaks of the designed reference ({name}): {d['peaks']}; runtime {d['runtime_s']:.1f} s")
p = json.load(open(f"{w}/pin/design.json"))
print()
print("pin J, d: designed expected sd", p["expected_sd"])
for f in p["fixed_experiments"]:
    print(f"  {f['input']}: expected sd {f['expected_sd']} within limits {f['within_limits']}")
PY
