#!/usr/bin/env python3
"""The spots found against the truths: for each encoder case (the eleventh set's damaged lines,
the twelfth set's missing pulses), the truth's dip (ε, its span, the line's angle −φ mod 2π)
beside the model as given's spot (θ₀, w), the discovered law's balance, θ₀ and coefficient with
its 95% interval, and how far θ₀ lies from the line (wrapped), in radians and in the spot's w.

    spot_truth.py CASES_DIR REPORTS_DIR   (REPORTS_DIR/CASE.json, whole-command reports)"""
import json, math, os, re, sys

cases, reports = sys.argv[1], sys.argv[2]
print("| case | ε | span [rad] | line at [rad] | as given: θ₀, w | law | θ₀ − line [rad] | in w | coefficient [95%] |")
print("|---|---|---|---|---|---|---|---|---|")
near = within_w = total = 0
for d in sorted(os.listdir(cases)):
    name = os.path.join(reports, d + ".json")
    if not d.startswith("encoder_missing") or not os.path.exists(name):
        continue
    a = json.load(open(os.path.join(cases, d, "answer.json")))
    t = a["truth"]
    value = lambda k: float(re.search(rf"{k}: ([0-9.e-]+)", t).group(1))
    eps, line = value("eps"), (-value("phase")) % (2 * math.pi)
    span = f"{value('span'):.2f}" if "span" in t else "0.3 (Gaussian)"
    r = json.load(open(name))
    g = (r.get("unexplained_as_given") or {}).get("fingerprint", {})
    law = r.get("discovered") or {}
    theta = law.get("theta_0", g.get("theta_0"))
    w = law.get("w", g.get("w"))
    off = "—" if theta is None else (theta - line + math.pi) % (2 * math.pi) - math.pi
    total += 1
    if theta is not None:
        near += abs(off) <= w / 2
        within_w += abs(off) <= w
    # The spot's function, in the law's first balance or in `also` (a law in two balances).
    parts = [law] + law.get("also", []) if law else []
    f = next((g for p in parts for g in p["functions"] if g["name"].startswith("omega*exp")),
             (law.get("functions") or [{}])[0])
    coef = f"{f['coefficient']:.4f} [{f['q025']:.4f}, {f['q975']:.4f}]" if f else "—"
    given = f"{g['theta_0']:.3f}, {g['w']:.3f}" if "theta_0" in g else g.get("kind", "—")
    print(f"| {d} | {eps:.3f} | {span} | {line:.3f} | {given} | {' + '.join(p['balance'] for p in parts) or '—'} | "
          f"{'—' if theta is None else f'{off:+.3f}'} | {'—' if theta is None else f'{abs(off) / w:.2f}'} | {coef} |")
print(f"\n{total} cases; a spot's θ₀ within w/2 of the line on {near}, within w on {within_w}")
