"""min bulk-ESS per second of total time, motorcal over nutpie, from the files beside this script.

nutpie: tune + draw (compilation excluded), CPU time of its process (`cpu_sample_s`) and wall time
(`sample_wall_s`). motorcal: MAP + initial points + warm-up + sampling (`total_cpu_s`, `wall_s`).
Each nutpie seed is paired with the motorcal runs whose time span overlaps its sampling (from
times.log); the median over all motorcal runs of the session is printed too.

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
        spans.setdefault(int(w[1]), {})[w[2]] = float(w[3])
    elif w[:1] == ["nutpie"]:
        ends[int(w[2])] = float(w[4])

ours = {i: {r["sampler"]: r for r in json.load(open(os.path.join(HERE, f"motorcal_k9_run{i}.json")))}
        for i in spans}
samplers = ["hmc-dense", "nuts-dense", "mala", "fisher-mala"]
print("nutpie seed | nutpie min ESS, R-hat, ESS/CPU-s, ESS/wall-s | motorcal runs overlapping | "
      + " | ".join(f"{s} ESS/CPU-s (×), ESS/wall-s (×)" for s in samplers))
for seed, end in sorted(ends.items()):
    n = json.load(open(os.path.join(HERE, f"nutpie_k9_s{seed}.json")))
    n_cpu = n["min_ess_bulk"] / n["cpu_sample_s"]
    n_wall = n["min_ess_bulk"] / n["sample_wall_s"]
    start = end - n["sample_wall_s"]
    runs = [i for i, s in spans.items() if s["start"] < end and s["end"] > start]
    cells = []
    for s in samplers:
        cpu = statistics.median(ours[i][s]["min_ess_per_total_s"] for i in runs)
        wall = statistics.median(ours[i][s]["min_ess_per_wall_s"] for i in runs)
        cells.append(f"{cpu:.0f} ({sig2(cpu / n_cpu)}×), {wall:.0f} ({sig2(wall / n_wall)}×)")
    print(f"{seed} | {n['min_ess_bulk']:.0f}, {n['max_rhat']:.3f}, {n_cpu:.0f}, {n_wall:.0f} | "
          f"{','.join(map(str, runs))} | " + " | ".join(cells))
print("median over all motorcal runs of the session:")
nutpie = [json.load(open(os.path.join(HERE, f"nutpie_k9_s{s}.json"))) for s in sorted(ends)]
n_cpu = statistics.median(n["min_ess_bulk"] / n["cpu_sample_s"] for n in nutpie)
n_wall = statistics.median(n["min_ess_bulk"] / n["sample_wall_s"] for n in nutpie)
for s in samplers:
    cpu = statistics.median(r[s]["min_ess_per_total_s"] for r in ours.values())
    wall = statistics.median(r[s]["min_ess_per_wall_s"] for r in ours.values())
    print(f"  {s}: {cpu:.0f} per CPU-s = {sig2(cpu / n_cpu)}× nutpie's median {n_cpu:.0f}; "
          f"{wall:.0f} per wall-s = {sig2(wall / n_wall)}× nutpie's median {n_wall:.0f}")
