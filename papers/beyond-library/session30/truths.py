#!/usr/bin/env python3
"""The thirteenth set's truths against what a run found: for the coupling capacitor, 1/τ
against the law's θ coefficient in what is read of ω (−1/τ to first order, while t ≪ τ) and its
95% interval; for the clutch, the engagement instant t_e against the knocks' instants; for the
loose part, the generator's knock instants (one a 40-ms window) against those found.

    truths.py CASES_ROOT RUN   (CASES_ROOT/SET/CASE/answer.json, RUN/CASE.json)"""
import glob, json, os, re, sys

root, run = sys.argv[1:3]
M = (1 << 64) - 1


def mix(z):
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M
    return z ^ (z >> 31)


def knock(salt, n):  # the generator's salted_uniform and window
    u = (mix(salt ^ (((n + 7) * 0x9E3779B97F4A7C15) & M)) >> 11) / (1 << 53)
    return 0.04 * n + 0.9 * 0.04 * u


def knocks_of(r, key):
    u = r.get(key)
    if not u or "jolted" not in u["suggestion"]:
        return []
    return [float(t) for t in u["suggestion"].split("t = ")[1].split(" s)")[0].replace("…", "").split(",") if t.strip()]


for d in sorted(glob.glob(f"{root}/*/*/")):
    n = os.path.basename(d[:-1])
    if not re.match(r"(ac_coupled_tacho|clutch_engagement|loose_part)-", n) or not os.path.exists(f"{run}/{n}.json"):
        continue
    truth = json.load(open(d + "answer.json"))["truth"]
    r = json.load(open(f"{run}/{n}.json"))
    if n.startswith("ac_coupled"):
        tau = float(re.search(r"tau: ([\d.e-]+)", truth).group(1))
        law = r.get("discovered")
        f = [x for x in (law or {}).get("functions", []) if x["name"] == "theta"]
        found = f"{-f[0]['coefficient']:.4f} [{-f[0]['q975']:.4f}, {-f[0]['q025']:.4f}]" if f else "no law in theta"
        print(f"{n}: 1/tau {1 / tau:.4f}; the law's -coefficient of theta {found}")
    elif n.startswith("clutch"):
        t_e = float(re.search(r"t_e: ([\d.e-]+)", truth).group(1))
        given, after = knocks_of(r, "unexplained_as_given"), knocks_of(r, "unexplained")
        ms = lambda ks: [round(1e3 * (k - t_e), 1) for k in ks]
        print(f"{n}: t_e {t_e:.4f} s; knocks as given {given} ({ms(given)} ms after t_e), after {after} ({ms(after)} ms)")
    else:
        salt = int(re.search(r"salt: (\d+)", truth).group(1))
        true = [round(knock(salt, k), 4) for k in range(13) if knock(salt, k) < 0.5]
        found = knocks_of(r, "unexplained_as_given")
        near = [round(1e3 * min((k - t for t in true), key=abs), 1) for k in found]
        print(f"{n}: true knocks {true}; found as given {found} ({near} ms from the nearest true one)")
