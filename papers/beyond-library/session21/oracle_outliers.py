#!/usr/bin/env python3
"""What an oracle finds of an encoder's miscounts: the contaminated normal of
src/discover/unexplained/outliers.rs (two-component EM, its gain in nats over the single
normal, less ln N = ln 1002 for its two degrees of freedom) on the true residual of ω alone:
the noise the recording drew (recording − truth) plus the miscounts themselves (recomputed from
the case's salt as examples/beyond_library_cases.rs draws them), no model fitted. Where even
this leaves the gain under ln N + 2, no detector of the verdict's kind can find them on that
record: the miss is spent on where the spikes are.

    oracle_outliers.py CASE_DIR ...
"""
import csv, math, sys

from miscounts import case_truth, miscounted



def ln_normal(y, s):
    return -0.5 * (y / s) ** 2 - math.log(s) - 0.5 * math.log(2 * math.pi)


def contaminated_gain(y):
    n = len(y)
    a0 = math.sqrt(sum(v * v for v in y) / n)
    single = sum(ln_normal(v, a0) for v in y)
    far = [v for v in y if abs(v) > 3.5 * a0]
    if not far:
        return 0.0
    eps, b, a = len(far) / n, math.sqrt(sum(v * v for v in far) / len(far)), a0
    ln_l = -math.inf
    for _ in range(200):
        r, total = [], 0.0
        for v in y:
            c, w = math.log(1 - eps) + ln_normal(v, a), math.log(eps) + ln_normal(v, b)
            t = max(c, w); s = t + math.log(math.exp(c - t) + math.exp(w - t))
            r.append(math.exp(w - s)); total += s
        if abs(total - ln_l) < 1e-9:
            break
        ln_l = total
        eps = min(max(sum(r) / n, 0.5 / n), 0.1)
        a = math.sqrt(sum((1 - ri) * v * v for ri, v in zip(r, y)) / sum(1 - ri for ri in r))
        b = max(math.sqrt(sum(ri * v * v for ri, v in zip(r, y)) / max(sum(r), 1e-300)), 2 * a)
    return ln_l - single


def rows(path):
    return [(float(r["t"]), float(r["omega"])) for r in csv.DictReader(open(path))]


pays = math.log(1002)
print(f"| case | spikes | size (σ) | miss (nats) | oracle gain | less ln N ({pays:.2f}) |")
print("|---|---|---|---|---|---|")
for case in sys.argv[1:]:
    answer, salt, a = case_truth(case)
    rec, truth = rows(f"{case}/recording.csv"), rows(f"{case}/truth.csv")
    spikes = [k for k in range(len(rec)) if miscounted(salt, k)]
    y = [(r[1] - t[1]) / 10.0 for r, t in zip(rec, truth)]
    for k in spikes:
        # truth.csv holds the miscount: the residual of the true motor is noise plus it.
        y[k] += (truth[k][1] - (truth[k - 1][1] + truth[k + 1][1]) / 2) / 10.0 if 0 < k < len(y) - 1 else 0.0
    g = contaminated_gain(y)
    print(f"| {case.rstrip('/').split('/')[-1]} | {len(spikes)} | {a / 10:.2f} | {answer['miss_nats']:.1f} | {g:.2f} | {g - pays:.2f} |")
