"""The overhead of the Python call over the command line on a K = 9 fit, by interleaved
repeats: the same fit (BM2(K = 9), NUTS dense, 4 chains × 1000 draws, seed 1) as
`motorcal fit --quiet` in a process of its own, and as `motorcal.fit` in a fresh Python
process (the imports of arviz and motorcal timed apart), one after the other, `--repeats` times; then the medians.

    python examples/python/overhead.py [--repeats 5] [--binary target/release/motorcal]

The command line also writes its draws, fit.json, the predictive CSV and four figures; the
Python call returns the arrays and writes nothing (`out=` would write the draws).
"""

import argparse
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import motorcal

NOMINAL = {
    "schema": 1,
    "motor": {"R": 0.1, "c_m": 0.01, "c_g": 0.009, "U": 24.0, "d": 1e-6, "L": 1e-4,
              "J": 5e-5, "I0": 0.0, "omega0": 0.0},
}

PYTHON_FIT = """
import time
started = time.perf_counter()
import arviz, motorcal
imported = time.perf_counter()
model = motorcal.Model.from_toml({model!r})
idata = motorcal.fit(motorcal.Recording.from_csv({data!r}, model), model, k=9, seed=1)
print(imported - started, time.perf_counter() - imported)
"""


def timed(command):
    started = time.perf_counter()
    result = subprocess.run(command, check=True, capture_output=True, text=True)
    return time.perf_counter() - started, result.stdout


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--binary", default="target/release/motorcal")
    args = parser.parse_args()
    root = pathlib.Path(tempfile.mkdtemp())
    motorcal.simulate(seed=1).to_csv(root / "recording.csv")
    motorcal.Model.from_dict(NOMINAL).write(root / "motor.toml")
    data, model = str(root / "recording.csv"), str(root / "motor.toml")
    cli = [args.binary, "fit", "--data", data, "--model", model, "--k", "9", "--seed", "1",
           "--quiet", "--out", str(root / "out")]
    python = [sys.executable, "-c", PYTHON_FIT.format(model=model, data=data)]
    times = {"cli": [], "python": [], "imports": [], "python_call": []}
    for i in range(args.repeats):
        t, _ = timed(cli)
        times["cli"].append(t)
        t, printed = timed(python)
        times["python"].append(t)
        imports, call = (float(v) for v in printed.split())
        times["imports"].append(imports)
        times["python_call"].append(call)
        print(f"repeat {i + 1}: command line {times['cli'][-1]:.3f} s, python process "
              f"{times['python'][-1]:.3f} s (import arviz, motorcal {imports:.3f} s, "
              f"the call {call:.3f} s)")
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"median of {args.repeats}: command line {med['cli']:.3f} s; python process "
          f"{med['python']:.3f} s ({med['python'] - med['cli']:+.3f} s), of which the imports "
          f"{med['imports']:.3f} s and the call {med['python_call']:.3f} s "
          f"({med['python_call'] - med['cli']:+.3f} s, "
          f"{100 * (med['python_call'] / med['cli'] - 1):+.1f}% over the command line)")


if __name__ == "__main__":
    main()
