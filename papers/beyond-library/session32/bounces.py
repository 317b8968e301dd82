#!/usr/bin/env python3
"""Session 32: the brush bounces of each brush_bounce case in CASES against what one knock must
gain — per case, its miss (answer.json's miss_nats, the noise-free truth against the nominal
model), how many 25-ms windows bounce (the generator's sign draw of its salt, as
`beyond_library_cases` makes them), the miss per bounce, and a first knock's price ½·ln N +
ln K (N = 1002 observations, K the 500 candidate instants at most, `unexplained::knocks`).

    bounces.py CASES [CASES …]"""
import glob, json, math, os, re, sys

M = (1 << 64) - 1


def mix(z):
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & M
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & M
    return z ^ (z >> 31)


price = 0.5 * math.log(1002) + math.log(500)
print(f"| case | miss (nats) | bounces | miss per bounce | a first knock's price ({price:.1f} nats) |")
print("|---|---|---|---|---|")
for cases in sys.argv[1:]:
    for d in sorted(glob.glob(f"{cases}/brush_bounce-*")):
        a = json.load(open(f"{d}/answer.json"))
        salt = int(re.search(r"salt: (\d+)", a["truth"]).group(1))
        n = sum(mix((salt + (k + 1) * 0x9E3779B97F4A7C15) & M) >> 63 == 1 for k in range(20))
        miss = a["miss_nats"]
        print(f"| {os.path.basename(d)} | {miss:.1f} | {n} | {miss / n:.1f} | "
              f"{'below' if miss / n < price else 'above'} |")
