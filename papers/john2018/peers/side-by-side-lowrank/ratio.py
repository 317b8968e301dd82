"""min bulk-ESS per CPU second of the whole cost, motorcal's samplers over nutpie low-rank, from
the files run.sh wrote.

nutpie: tune + draw (its compilation excluded), CPU time of its process (`cpu_sample_s`).
motorcal: MAP + initial points + warm-up + sampling (`total_cpu_s` via `min_ess_per_total_s`).
Each nutpie run is paired with the motorcal runs at the same K whose time span overlaps its
sampling (from times.log); the median over all of the session's motorcal runs at that K too.

usage: python3 ratio.py [DIR]   (DIR: the folder of the files; this script's own by default)
"""
import json, math, os, statistics, sys

HERE = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))


def sig2(x):
    if not (x > 0 and math.isfinite(x)):
        return str(x)
    digits = 1 - math.floor(math.log10(x))
    r = round(x, digits)
    digits = 1 - math.floor(math.log10(r))
    return f"{r:.{max(digits, 0)}f}"


spans, ends = {}, {}
for line in open(os.path.join(HERE, "times.log")):
    w = line.split()
    if w[:1] == ["ours"]:
        spans.setdefault((int(w[2]), int(w[4])), {})[w[5]] = float(w[6])
    elif w[:1] == ["nutpie"]:
        ends[(int(w[2]), int(w[4]))] = float(w[6])

for k in sorted({k for k, _ in ends}):
    runs_k = {i: {r["sampler"]: r for r in json.load(open(os.path.join(HERE, f"motorcal_k{k}_run{i}.json")))}
              for (kk, i), s in spans.items() if kk == k and "end" in s}
    samplers = list(next(iter(runs_k.values())).keys())
    print(f"K = {k}")
    print("nutpie seed | nutpie min ESS, R-hat, ESS/CPU-s | motorcal runs overlapping | "
          + " | ".join(f"{s} ESS/CPU-s, R-hat, k̂ (× nutpie)" for s in samplers))
    nutpie_rates = []
    for (kk, seed), end in sorted(ends.items()):
        if kk != k:
            continue
        n = json.load(open(os.path.join(HERE, f"nutpie_k{k}_s{seed}.json")))
        n_cpu = n["min_ess_bulk"] / n["cpu_sample_s"]
        nutpie_rates.append(n_cpu)
        start = end - n["sample_wall_s"]
        runs = [i for i in runs_k if spans[(k, i)]["start"] < end and spans[(k, i)]["end"] > start]
        cells = []
        for s in samplers:
            if not runs:
                cells.append("no run overlapped")
                continue
            cpu = statistics.median(runs_k[i][s]["min_ess_per_total_s"] for i in runs)
            rhat = max(runs_k[i][s]["max_rhat"] for i in runs)
            khat = [runs_k[i][s].get("khat") for i in runs]
            khat = "-" if khat[0] is None else f"{max(khat):.2f}"
            cells.append(f"{cpu:.0f}, {rhat:.3f}, {khat} ({sig2(cpu / n_cpu)}×)")
        print(f"{seed} | {n['min_ess_bulk']:.0f}, {n['max_rhat']:.3f}, {n_cpu:.0f} | "
              f"{','.join(map(str, runs))} | " + " | ".join(cells))
    n_med = statistics.median(nutpie_rates)
    print(f"median over the {len(runs_k)} motorcal runs at K = {k}:")
    for s in samplers:
        cpu = statistics.median(r[s]["min_ess_per_total_s"] for r in runs_k.values())
        per_solve = statistics.median(r[s]["min_ess_per_solve"] for r in runs_k.values())
        print(f"  {s}: {cpu:.0f} per CPU-s of the whole cost = {sig2(cpu / n_med)}× nutpie low-rank's "
              f"median {n_med:.0f}; min-ESS per solve-equivalent {per_solve:.2f}")
