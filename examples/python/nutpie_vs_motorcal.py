"""nutpie and motorcal's NUTS on the same posterior, from Python, with ESS per second side by
side.

nutpie samples through `motorcal.Posterior.log_density_gradient` (its python-function
interface: every gradient is a Python call into the Rust posterior); motorcal's NUTS runs in
Rust on the Laplace metric. Both on BM2(K) of the paper's synthetic data (501 samples,
c_g = 0.009 believed, 0.01 true). ESS is ArviZ's bulk ESS, minimum over the parameters,
computed on the same coordinates (the reported quantities: R, σ, a) for both.

    pip install ./python nutpie arviz
    python examples/python/nutpie_vs_motorcal.py [--k 9] [--chains 4] [--draws 1000] [--seed 1]
"""

import argparse
import time

import arviz
import numpy as np

import motorcal

NOMINAL = {
    "schema": 1,
    "motor": {"R": 0.1, "c_m": 0.01, "c_g": 0.009, "U": 24.0, "d": 1e-6, "L": 1e-4,
              "J": 5e-5, "I0": 0.0, "omega0": 0.0},
}


def nutpie_run(recording, model, k, chains, draws, tune, seed):
    import nutpie
    from nutpie.compiled_pyfunc import from_pyfunc

    probe = motorcal.Posterior(recording, model, k=k)
    names = probe.output_names
    start = probe.map()["x"]

    def make_logp_fn():
        # One posterior per chain: nutpie calls from several threads, each its own.
        posterior = motorcal.Posterior(recording, model, k=k)

        def logp(x, **_):
            return posterior.log_density_gradient(x)

        return logp

    def make_expand_fn(*_):
        posterior = motorcal.Posterior(recording, model, k=k)

        def expand(x, **_):
            values = posterior.constrain(x)
            return {name: np.asarray(values[j]) for j, name in enumerate(names)}

        return expand

    def initial_point(seed):
        rng = np.random.default_rng(seed)
        return start + 0.1 * probe.map()["laplace_sd"] * rng.standard_normal(len(start))

    compiled = from_pyfunc(
        probe.dim,
        make_logp_fn,
        make_expand_fn,
        [np.dtype("float64")] * len(names),
        [()] * len(names),
        names,
        make_initial_point_fn=initial_point,
    )
    started = time.perf_counter()
    idata = nutpie.sample(
        compiled, chains=chains, draws=draws, tune=tune, seed=seed, progress_bar=False
    )
    return idata, time.perf_counter() - started


def min_ess(idata):
    return float(arviz.ess(idata, method="bulk").to_array().min())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--k", type=int, default=9)
    parser.add_argument("--chains", type=int, default=4)
    parser.add_argument("--draws", type=int, default=1000)
    parser.add_argument("--nutpie-tune", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()

    recording = motorcal.simulate(seed=args.seed)
    model = motorcal.Model.from_dict(NOMINAL)

    started = time.perf_counter()
    ours = motorcal.fit(recording, model, k=args.k, chains=args.chains, draws=args.draws,
                        seed=args.seed)
    our_wall = time.perf_counter() - started
    theirs, their_wall = nutpie_run(recording, model, args.k, args.chains, args.draws,
                                    args.nutpie_tune, args.seed)

    print(f"BM2(K = {args.k}), {args.chains} chains × {args.draws} draws, seed {args.seed}")
    print(f"{'sampler':<34} {'min bulk ESS':>12} {'wall s':>8} {'ESS/s':>8} {'max R-hat':>9}")
    for label, idata, wall in [
        ("motorcal nuts-dense (Laplace)", ours, our_wall),
        (f"nutpie (python logp, tune {args.nutpie_tune})", theirs, their_wall),
    ]:
        ess = min_ess(idata)
        rhat = float(arviz.rhat(idata).to_array().max())
        print(f"{label:<34} {ess:>12.0f} {wall:>8.2f} {ess / wall:>8.1f} {rhat:>9.4f}")
    print(f"nutpie gradients: {int(theirs.sample_stats.n_steps.sum())} in sampling; "
          f"motorcal: {ours.cost['evaluations']} in sampling, {ours.cost['all_evaluations']} all")


if __name__ == "__main__":
    main()
