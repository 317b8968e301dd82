"""`diagnose` against the command on the two concealed cases the repository ships, and
`simulate`, `bench` and `sweep` as Python data."""

import json
import subprocess

import pytest

import motorcal
from conftest import CASES


@pytest.mark.parametrize("case", ["coulomb_friction", "torque_constant"])
def test_diagnose_selects_and_scores_as_the_command(binary, case, tmp_path):
    data, model_path = CASES / case / "recording.csv", CASES / case / "motor.toml"
    out = tmp_path / "diagnosis.json"
    subprocess.run(
        [binary, "diagnose", "--data", data, "--model", model_path, "--rank-only", "--quiet",
         "--json", out],
        check=True,
        capture_output=True,
    )
    theirs = json.loads(out.read_text())
    model = motorcal.Model.from_toml(model_path)
    report, amended = motorcal.diagnose(
        motorcal.Recording.from_csv(data, model), model, rank_only=True
    )
    assert report["selected"] == theirs["selected"] == case
    assert report["selected_set"] == theirs["selected_set"]
    assert [(r["effect"], r["score"]) for r in report["ranking"]] == [
        (r["effect"], r["score"]) for r in theirs["ranking"]
    ]
    # The same contract: every key the command writes (runtime and outputs aside).
    assert set(report) == set(theirs)
    assert amended is None or case in amended.terms


def test_simulate_is_the_commands_recording(binary, tmp_path):
    subprocess.run(
        [binary, "simulate", "--out", tmp_path, "--seed", "9", "--input", "step"],
        check=True,
        capture_output=True,
    )
    theirs = motorcal.Recording.from_csv(tmp_path / "recording.csv")
    mine = motorcal.simulate(seed=9, input="step")
    for name, values in mine.columns().items():
        assert (values == theirs.columns()[name]).all(), name
    with pytest.raises(ValueError, match=r"^input = ramp: expected one of constant"):
        motorcal.simulate(input="ramp")


def test_sweep_records_are_the_commands(binary, tmp_path):
    out = tmp_path / "sweep.json"
    subprocess.run(
        [binary, "sweep", "--k", "1,2", "--chains", "2", "--draws", "100", "--quiet",
         "--json", out, "--out", tmp_path / "sweep"],
        check=True,
        capture_output=True,
    )
    theirs = json.loads(out.read_text())
    theirs = theirs["records"] if isinstance(theirs, dict) else theirs
    mine = motorcal.sweep(k=[1, 2], chains=2, draws=100)
    assert [r["k"] for r in mine] == [r["k"] for r in theirs] == [1, 2]
    for a, b in zip(mine, theirs):
        # The same draws: every figure but the times.
        for key in ("r", "sigma_i", "sigma_omega", "delta_i", "max_rhat", "min_ess_bulk",
                    "evidence"):
            assert a[key] == b[key], key


def test_bench_is_a_list_of_records():
    records = motorcal.bench(k=[0], samplers=["nuts-dense"], threads=[1], chains=2, draws=100)
    assert len(records) == 1
    assert (records[0]["sampler"], records[0]["k"], records[0]["threads"]) == ("nuts-dense", 0, 1)
    assert records[0]["min_ess_per_s"] > 0 and records[0]["all_evaluations"] > 0
