"""What a supply's dips left after a library term can give a sinusoid searched as the verdict
searches it (src/study/frequency_grid.rs: four points per Fourier spacing from two periods over
the record to Nyquist; ln G for the frequency and ½·ln N per coefficient), against what the
library's terms leave noise-free (session23/library-residual-820000.md). A sinusoid's gain on
the noisy record is ½·χ'²₂ with noncentrality 2·L for the L nats of the noise-free miss that
it holds: its mean is L + 1. L is at most what the term leaves, and on a pulse train of duty
D it is at most the fundamental's share of its alternating power, 2·sin²(π·D)/(π²·D·(1 − D)),
where the motor's dynamics do not filter the harmonics out first (they do, on ω), so both bounds are shown.

python3 dips_bound.py   (from papers/beyond-library/session25)"""
import math
import re

span, n, channels, threshold, duty = 0.5, 501, 2, 2.0, 0.3
nyquist = 0.5 / (span / (n - 1))
f_min, step = 2.0 / span, 1.0 / (4.0 * span)
grid = int(math.floor((nyquist - f_min) / step - 1e-12)) + 1
ln_n = math.log(n * channels)
price = 2 * 0.5 * ln_n + math.log(grid)  # ½·ln N per coefficient, ln G for the frequency (oscillation.rs)
share = 2 * math.sin(math.pi * duty) ** 2 / (math.pi ** 2 * duty * (1 - duty))
print(f"grid {grid} frequencies; a searched sinusoid pays {price:.1f} nats, with the threshold "
      f"{price + threshold:.1f}; a {duty:.0%} pulse train's fundamental holds {share:.0%} of its "
      "alternating power")
rows = open("../session23/library-residual-820000.md").read().splitlines()
print("| case | term | left noise-free (nats) | mean gain, all of it one sinusoid | "
      "mean gain, the fundamental's share | clears the price on average |")
print("|---|---|---|---|---|---|")
selected = {"supply_dips-820002": "back_emf_constant", "supply_dips-820006": "speed_gain"}
for line in rows:
    cells = [c.strip() for c in line.strip("|").split("|")]
    if cells[0] not in selected:
        continue
    for term, left in [(cells[2], cells[3]), (cells[4], cells[5])]:
        if term != selected[cells[0]]:
            continue
        left = float(left)
        whole, fundamental = left + 1.0, share * left + 1.0
        verdict = ("no" if whole < price + threshold else
                   "only if most of it is one sinusoid" if fundamental < price + threshold else "yes")
        print(f"| {cells[0]} | {term} (selected) | {left:.1f} | {whole:.1f} | {fundamental:.1f} | {verdict} |")
