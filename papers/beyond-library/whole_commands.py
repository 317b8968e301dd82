#!/usr/bin/env python3
"""The whole-command reports of `motorcal diagnose --json REPORT --out DIR` on the
independent-integrator cases: the runtime each printed (`runtime_s`), and, where a law was
discovered, σ after it (`fit_after.sigma`) over the record's own noise, the standard deviation
of recording.csv − truth.csv per channel (the generator's noise-free truth beside each case).

    whole_commands.py [--cases NAME,NAME…] REPORTS_DIR CASES_DIR [CASES_DIR …]

With --cases, the runtime of each case named is printed too (a case quoted before and after a
change, whatever its place in the run).

REPORTS_DIR holds NAME.json for each case folder NAME found under the CASES_DIRs."""
import csv, glob, json, math, os, statistics, sys

args = sys.argv[1:]
named = []
if args and args[0] == "--cases":
    named, args = args[1].split(","), args[2:]
reports, case_dirs = args[0], args[1:]
cases = {os.path.basename(os.path.dirname(d)): d for c in case_dirs for d in glob.glob(f"{c}/*/")}

def own_noise(case):
    rec = list(csv.DictReader(open(os.path.join(cases[case], "recording.csv"))))
    tru = list(csv.DictReader(open(os.path.join(cases[case], "truth.csv"))))
    out = {}
    for ch in ("I", "omega"):
        d = [float(a[ch]) - float(b[ch]) for a, b in zip(rec, tru)]
        m = sum(d) / len(d)
        out[ch] = math.sqrt(sum((x - m) ** 2 for x in d) / len(d))
    return out

runs = {}
for p in sorted(glob.glob(f"{reports}/*.json")):
    name = os.path.basename(p)[:-5]
    if name in cases:
        runs[name] = json.load(open(p))
times = sorted((r["runtime_s"], n) for n, r in runs.items())
print(f"{len(times)} whole commands: runtime max {times[-1][0]:.1f} s ({times[-1][1]}), "
      f"median {statistics.median(t for t, _ in times):.1f} s; over 30 s: "
      f"{sum(t > 30 for t, _ in times)}")
print("slowest five: " + ", ".join(f"{name} {t:.1f} s" for t, name in reversed(times[-5:])))
if named:
    print("named: " + ", ".join(f"{name} {runs[name]['runtime_s']:.1f} s" for name in named if name in runs))
print("\n| case | law's balance | σ_I after / own noise | σ_ω after / own noise | within 10% |")
print("|---|---|---|---|---|")
n = ok = 0
for name, r in sorted(runs.items()):
    if not r.get("discovered"):
        continue
    noise = own_noise(name)
    ratio = {ch: r["fit_after"]["sigma"][ch] / noise[ch] for ch in noise}
    good = all(abs(x - 1) <= 0.10 for x in ratio.values())
    n += 1
    ok += good
    print(f"| {name} | {r['discovered']['balance']} | {ratio['I']:.3f} | {ratio['omega']:.3f} | "
          f"{'yes' if good else '**no**'} |")
print(f"\n{ok} of {n} within 10% of the record's own noise")
