"""motorcal from Python: Bayesian calibration of a DC-motor model that learns its own
discrepancy, with the library's gradient-aware samplers.

    import motorcal
    model = motorcal.Model.from_toml("motor.toml")
    rec = motorcal.Recording.from_csv("recording.csv", model)
    idata = motorcal.fit(rec, model, bm=2, k=9, chains=4, draws=1000, seed=1)
    print(idata.log_evidence_laplace, arviz.summary(idata))

Everything is the Rust library's (the same calls the ``motorcal`` command makes): the same
options give the same draws, bit for bit. Bad input raises ``ValueError`` with the library's
one-line message (file, line, field); Ctrl-C stops a run and raises ``KeyboardInterrupt``.
No progress bars are drawn from Python.
"""

from __future__ import annotations

import sys

from . import _motorcal
from ._motorcal import (
    DEFAULT_SEED,
    SAMPLERS,
    Model,
    Posterior,
    Recording,
    __version__,
    bench,
    diagnose,
    log_density,
    log_density_gradient,
    simulate,
    sweep,
)

__all__ = [
    "DEFAULT_SEED",
    "SAMPLERS",
    "Model",
    "Posterior",
    "Recording",
    "__version__",
    "bench",
    "diagnose",
    "fit",
    "log_density",
    "log_density_gradient",
    "simulate",
    "sweep",
]

# CmdStan's sampler columns and the names ArviZ's from_cmdstan gives them in sample_stats.
CMDSTAN_TO_ARVIZ = {
    "lp__": "lp",
    "accept_stat__": "acceptance_rate",
    "stepsize__": "step_size",
    "treedepth__": "tree_depth",
    "n_leapfrog__": "n_steps",
    "divergent__": "diverging",
    "energy__": "energy",
}

# What a fit reports beside its draws; attributes of the result.
_FIGURES = (
    "map",
    "map_log_density",
    "map_log_likelihood",
    "log_evidence_laplace",
    "posterior_mean_log_likelihood",
    "cost",
    "summaries",
    "max_rhat",
    "min_ess_bulk",
    "divergences",
    "wall_seconds",
    "model",
    "sampler",
    "outputs",
)


class FitResult(dict):
    """A fit as NumPy arrays, when ArviZ is not installed: ``posterior`` (name → array of shape
    (chains, draws)), ``sample_stats`` (CmdStan's column names), ``observed_data``,
    ``unconstrained``; the MAP, the Laplace evidence and the cost as attributes too."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def fit(
    recordings,
    model,
    bm=None,
    k=None,
    sampler="nuts-dense",
    chains=4,
    warmup=None,
    draws=1000,
    keep=None,
    seed=DEFAULT_SEED,
    threads=None,
    metric_adaptation=None,
    prior_family="laplace",
    prior_decay=0.0,
    force=False,
    out=None,
    save_warmup=True,
    posterior_predictive=True,
    progress=True,
    inference_data=None,
):
    """Calibrate ``model`` on ``recordings`` (one or a list) as ``motorcal fit`` does: the MAP
    and its Laplace evidence, then ``chains`` chains of ``sampler`` from ``seed``.

    ``bm``/``k`` default to the model file's ``[discrepancy]``, else BM2 with K = 9; ``warmup``
    to the sampler's (100 for HMC/NUTS on the Laplace metric, else 1000). With ``out`` the
    draws are also written there as CmdStan CSV (``fit-<sampler>-chain<N>.csv``), after the run:
    an interrupted fit writes nothing.

    With ``progress`` a one-line bar on standard error counts the chains' transitions, redrawn
    in place (a terminal and a notebook's output cell alike).

    With ``posterior_predictive`` every kept draw also gives a replicated recording,
    G(θ) + δ + σ·ε (one solve a draw, the noise from ``seed``): the ``posterior_predictive``
    group, named like ``observed_data``.

    Returns ``arviz.InferenceData`` (posterior, sample_stats, observed_data and the
    ``unconstrained_posterior`` group of the sampler's coordinates, and with ``save_warmup``
    the warm-up's draws as ``warmup_posterior`` and ``warmup_sample_stats``) when ArviZ imports and
    ``inference_data`` is not False, else a :class:`FitResult` of NumPy arrays. Either way
    ``result.map`` ({coordinate: (value, laplace_sd)}), ``result.log_evidence_laplace``,
    ``result.cost`` (the whole cost: wall and CPU time per phase, evaluations, ESS per unit),
    ``result.summaries``, ``result.max_rhat`` … are attributes.
    """
    raw = _motorcal.fit_raw(
        recordings,
        model,
        bm=bm,
        k=k,
        sampler=sampler,
        chains=chains,
        warmup=warmup,
        draws=draws,
        keep=keep,
        seed=seed,
        threads=threads,
        metric_adaptation=metric_adaptation,
        prior_family=prior_family,
        prior_decay=prior_decay,
        force=force,
        out=None if out is None else str(out),
        save_warmup=save_warmup,
        posterior_predictive=posterior_predictive,
        show_progress=bool(progress),
    )
    names = raw["names"]
    posterior = {name: raw["draws"][:, :, j] for j, name in enumerate(names)}
    unconstrained = {
        name: raw["unconstrained"][:, :, j] for j, name in enumerate(raw["unconstrained_names"])
    }
    stats = _typed(raw["sample_stats"])
    warmup = None
    if "warmup_draws" in raw:
        warmup = {
            "posterior": {name: raw["warmup_draws"][:, :, j] for j, name in enumerate(names)},
            "sample_stats": _typed(raw["warmup_sample_stats"]),
        }
    figures = {key: raw[key] for key in _FIGURES}
    if inference_data is not False:
        try:
            import arviz
        except ImportError:
            if inference_data:
                raise
        else:
            return _inference_data(arviz, posterior, unconstrained, stats, warmup, raw, figures)
    result = FitResult(
        posterior=posterior,
        sample_stats=stats,
        observed_data=raw["observed_data"],
        unconstrained=unconstrained,
    )
    if "posterior_predictive" in raw:
        result["posterior_predictive"] = raw["posterior_predictive"]
    if warmup is not None:
        result["warmup_posterior"] = warmup["posterior"]
        result["warmup_sample_stats"] = warmup["sample_stats"]
    result.update(figures)
    return result


def _progress(label, done, total, finished):
    """One line of progress on standard error, rewritten in place; ended once the run has
    returned (`finished`), not when the count first reaches the total: the run still writes
    its draws and predictions after its last transition, and a redraw then must not end the
    line a second time."""
    width = 30
    filled = width * done // max(total, 1)
    bar = "#" * filled + "-" * (width - filled)
    end = "\n" if finished else ""
    sys.stderr.write(f"\r{label} [{bar}] {done}/{total} transitions{end}")
    sys.stderr.flush()


def _typed(stats):
    """CmdStan's columns with their types: integer tree depth and steps, boolean divergence."""
    stats = dict(stats)
    stats["treedepth__"] = stats["treedepth__"].astype("int64")
    stats["n_leapfrog__"] = stats["n_leapfrog__"].astype("int64")
    stats["divergent__"] = stats["divergent__"].astype(bool)
    return stats


def _arviz_names(stats):
    return {CMDSTAN_TO_ARVIZ[k]: v for k, v in stats.items()}


def _inference_data(arviz, posterior, unconstrained, stats, warmup, raw, figures):
    attrs = {
        "inference_library": "motorcal",
        "inference_library_version": __version__,
        "model": raw["model"],
        "sampler": raw["sampler"],
        "log_evidence_laplace": raw["log_evidence_laplace"],
        "map_log_density": raw["map_log_density"],
    }
    extra = {}
    if warmup is not None:
        extra = {
            "warmup_posterior": warmup["posterior"],
            "warmup_sample_stats": _arviz_names(warmup["sample_stats"]),
            "save_warmup": True,
        }
    if "posterior_predictive" in raw:
        extra["posterior_predictive"] = raw["posterior_predictive"]
    idata = arviz.from_dict(
        posterior=posterior,
        sample_stats=_arviz_names(stats),
        observed_data=raw["observed_data"],
        **extra,
    )
    idata.add_groups({"unconstrained_posterior": arviz.dict_to_dataset(unconstrained)})
    for group in ("posterior", "sample_stats", "unconstrained_posterior"):
        idata[group].attrs.update(attrs)
    for key, value in figures.items():
        object.__setattr__(idata, key, value)
    return idata
