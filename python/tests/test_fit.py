"""`fit` against the command line: the same draws bit for bit for the same seed and options,
ArviZ's summary equal to `motorcal summarize`'s, and an interrupted fit that stops cleanly."""

import json
import os
import signal
import subprocess
import threading

import numpy as np
import pytest

import motorcal

OPTIONS = {"k": 3, "chains": 2, "draws": 200, "seed": 11}


def read_cmdstan(path):
    """A CmdStan CSV: its column names and its rows as float64."""
    lines = [l for l in path.read_text().splitlines() if l and not l.startswith("#")]
    names = lines[0].split(",")
    rows = np.array([[float(v) for v in l.split(",")] for l in lines[1:]])
    return names, rows


@pytest.fixture(scope="module")
def cli_fit(binary, files, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli-fit")
    data, model = files
    flags = [f"--{k}={v}" for k, v in OPTIONS.items()]
    subprocess.run(
        [binary, "fit", "--data", data, "--model", model, "--quiet", "--out", out, *flags],
        check=True,
        capture_output=True,
    )
    return out


@pytest.fixture(scope="module")
def py_fit(files):
    data, model = files
    model = motorcal.Model.from_toml(model)
    return motorcal.fit(motorcal.Recording.from_csv(data, model), model, **OPTIONS)


def test_draws_are_the_command_lines_bit_for_bit(cli_fit, py_fit):
    arviz_names = {v: k for k, v in motorcal.CMDSTAN_TO_ARVIZ.items()}
    for chain in range(OPTIONS["chains"]):
        names, rows = read_cmdstan(cli_fit / f"fit-nuts-dense-chain{chain + 1}.csv")
        assert rows.shape[0] == OPTIONS["draws"]
        for j, name in enumerate(names):
            if name.endswith("__"):
                mine = py_fit.sample_stats[motorcal.CMDSTAN_TO_ARVIZ[name]].values[chain]
            else:
                mine = py_fit.posterior[name].values[chain]
            assert np.array_equal(mine.astype(float), rows[:, j]), name
        assert set(py_fit.posterior.data_vars) == {n for n in names if not n.endswith("__")}
        assert set(py_fit.sample_stats.data_vars) == set(arviz_names)


def test_arviz_summary_equals_motorcal_summarize(binary, cli_fit, py_fit, tmp_path):
    import arviz

    out = tmp_path / "summary.json"
    draws = sorted(cli_fit.glob("fit-nuts-dense-chain*.csv"))
    subprocess.run([binary, "summarize", *draws, "--json", out], check=True, capture_output=True)
    theirs = {s["name"]: s for s in json.loads(out.read_text())}
    summary = arviz.summary(py_fit, round_to="none")
    assert set(summary.index) == set(theirs)
    for name, row in summary.iterrows():
        for column in ("r_hat", "ess_bulk", "ess_tail", "mcse_mean", "mean", "sd"):
            key = {"r_hat": "rhat"}.get(column, column)
            assert row[column] == pytest.approx(theirs[name][key], rel=1e-9, abs=1e-12), (
                name,
                column,
            )


def test_the_fit_carries_the_map_evidence_and_cost(py_fit, files):
    assert set(py_fit.map) == set(py_fit.unconstrained_posterior.data_vars)
    assert np.isfinite(py_fit.log_evidence_laplace)
    cost = py_fit.cost
    assert cost["eval_kind"] == "gradient" and cost["all_evaluations"] > cost["evaluations"] > 0
    assert py_fit.max_rhat == max(s["rhat"] for s in py_fit.summaries)
    assert set(py_fit.observed_data.data_vars) == {"I", "omega"}
    assert py_fit.posterior.attrs["log_evidence_laplace"] == py_fit.log_evidence_laplace


def test_without_arviz_a_dict_of_arrays(recording, model):
    result = motorcal.fit(recording, model, bm=1, chains=2, draws=50, seed=3, inference_data=False)
    assert isinstance(result, motorcal.FitResult)
    assert result.posterior["R"].shape == (2, 50)
    assert result.sample_stats["divergent__"].dtype == bool
    assert set(result.sample_stats) == set(motorcal.CMDSTAN_TO_ARVIZ)
    assert np.isfinite(result.log_evidence_laplace)


def test_an_interrupted_fit_raises_and_writes_nothing(recording, model, tmp_path):
    out = tmp_path / "interrupted"
    # Python leaves SIGINT ignored when it started ignored (a background job of a
    # non-interactive shell, as CI may run us): install the default handler for this test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            motorcal.fit(
                recording, model, k=3, chains=2, draws=500_000, seed=1, out=out, progress=False
            )
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert not out.exists() or not any(out.iterdir())


def test_the_warmup_groups_hold_every_warmup_draw(py_fit):
    warmup = py_fit.warmup_posterior
    # 100: the Laplace metric's default warm-up for NUTS.
    assert warmup["R"].shape == (OPTIONS["chains"], 100)
    assert set(py_fit.warmup_sample_stats.data_vars) == set(motorcal.CMDSTAN_TO_ARVIZ.values())
    step = py_fit.warmup_sample_stats.step_size.values
    # Dual averaging moves the step size in warm-up; sampling keeps the one it settled on.
    assert len(np.unique(step[0])) > 1
    assert len(np.unique(py_fit.sample_stats.step_size.values[0])) == 1


def test_the_posterior_predictive_scatters_about_the_fit_by_its_noise(py_fit):
    """Each kept draw replicates the recording: named and shaped like the observed data, and
    across draws it spreads about the fit by the fitted noise σ (plus the little that θ and δ
    vary), not by nothing and not by more."""
    predictive = py_fit.posterior_predictive
    assert set(predictive.data_vars) == set(py_fit.observed_data.data_vars)
    for name in predictive.data_vars:
        values = predictive[name].values
        n = py_fit.observed_data[name].values.shape[0]
        assert values.shape == (OPTIONS["chains"], OPTIONS["draws"], n)
        sigma = py_fit.posterior[f"sigma_{name}"].values.mean()
        spread = values.reshape(-1, n).std(axis=0).mean()
        assert 0.9 * sigma < spread < 1.2 * sigma, (name, spread, sigma)


def test_a_redraw_at_the_total_does_not_end_the_line_before_the_run_returns(capfd):
    # On a loaded machine the count reached its total a redraw before the run returned, and
    # the line was ended twice (a clean-clone CI, 2026-11-29).
    motorcal._progress("fit", 800, 800, False)
    motorcal._progress("fit", 800, 800, True)
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and err.endswith("\n")


def test_progress_is_one_line_redrawn_and_ended_at_the_total(recording, model, capfd):
    motorcal.fit(recording, model, bm=1, chains=2, draws=300, seed=5, progress=True)
    err = capfd.readouterr().err
    # Each redraw starts with a carriage return; the last one says every transition is done.
    assert err.endswith("\n") and err.count("\n") == 1
    last = err.rstrip("\n").split("\r")[-1]
    total = 2 * (100 + 300)
    assert last.endswith(f"{total}/{total} transitions"), last
