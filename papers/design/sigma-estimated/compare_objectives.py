"""Prints, for each `motorcal design` command of two run.sh outputs (the search's objective at
the σ given, out.txt; profiled, out-profiled-objective.txt), the worst truth's expected gap
with σ estimated and the design's wall time; then the current-driven loop's expected gaps."""
import re
import sys

def designs(path):
    text = open(path).read()
    out = []
    for block in text.split("$ motorcal design ")[1:]:
        name = re.search(r"--out (\S+)", block).group(1)
        gap = re.search(r"designed input: expected gap ([-\d.]+) ± ([\d.]+)", block)
        wall = re.search(r"in ([\d.]+) s", block)
        out.append((name, float(gap.group(1)), float(gap.group(2)), float(wall.group(1))))
    loop = [float(g) for g in re.findall(r"\(truth\) vs \w+: designed ([\d.]+)", text)]
    return out, loop

a, la = designs(sys.argv[1] if len(sys.argv) > 1 else "out.txt")
b, lb = designs(sys.argv[2] if len(sys.argv) > 2 else "out-profiled-objective.txt")
print("design | at the σ given: gap, wall | profiled: gap, wall | difference")
for (n, g, s, w), (_, g2, s2, w2) in zip(a, b):
    print(f"{n} | {g:.2f} ± {s:.2f}, {w:.1f} s | {g2:.2f} ± {s2:.2f}, {w2:.1f} s | {g2 - g:+.2f}")
for x, y in zip(la, lb):
    print(f"current-driven | {x:.1f} | {y:.1f} | {y - x:+.1f}")
