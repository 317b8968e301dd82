#!/usr/bin/env python3
"""Session 31: the fourteenth set's time functions and arms against their truths — per case of
brake_release, current_offset_step and gravity_arm in CASES, the truth's τ_b, t_z or k beside
the model as given's fingerprint (τ, t_s, k) and the law discovered (its equation), and whether
the law's 95% interval holds the truth's size (a brake's −a on exp(-t/tau), a re-zeroing's b on
step(t-t_s)).

    truths.py CASES REPORTS   (REPORTS/CASE.json, `motorcal diagnose --json`)"""
import glob, json, os, re, sys

cases, reports = sys.argv[1:3]
print("| case | truth | as given | law discovered | interval holds the truth's size |")
print("|---|---|---|---|---|")
for d in sorted(glob.glob(f"{cases}/*")):
    name = os.path.basename(d)
    if not re.match(r"(brake_release|current_offset_step|gravity_arm)-", name):
        continue
    truth = json.load(open(f"{d}/answer.json"))["truth"]
    r = json.load(open(f"{reports}/{name}.json"))
    g = r.get("unexplained_as_given")
    f = g["fingerprint"] if g else {}
    shape = ", ".join(f"{k} {f[k]:.4g}" for k in ("tau", "t_s", "k") if k in f)
    given = f"{f.get('kind', '—')} {f.get('balance', '')} {shape}".strip()
    law = r["discovered"]["equation"] if r.get("discovered") else "—"
    size = {"brake_release": ("a", "exp(-t/tau)", -1.0), "current_offset_step": ("b", "step(t-t_s)", 1.0)}
    holds = "—"
    for effect, (key, function, sign) in size.items():
        if name.startswith(effect) and r.get("discovered"):
            value = sign * float(re.search(rf"{key}: ([-0-9.e]+)", truth).group(1))
            f = [f for f in r["discovered"]["functions"] if f["name"] == function]
            if f:
                holds = "yes" if f[0]["q025"] <= value <= f[0]["q975"] else "no"
    print(f"| {name} | {truth} | {given} | {law} | {holds} |")
