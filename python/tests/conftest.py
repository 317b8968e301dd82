"""Shared set-up: a small synthetic problem, the repository's fixtures and the `motorcal`
binary the Python results are compared with."""

import os
import pathlib
import subprocess

import pytest

import motorcal

REPO = pathlib.Path(__file__).resolve().parents[2]
CASES = REPO / "tests" / "fixtures" / "cases"

# The model a user would believe: the paper's motor with c_g = 0.009 (the data's is 0.01).
NOMINAL = {
    "schema": 1,
    "motor": {
        "R": 0.1,
        "c_m": 0.01,
        "c_g": 0.009,
        "U": 24.0,
        "d": 1e-6,
        "L": 1e-4,
        "J": 5e-5,
        "I0": 0.0,
        "omega0": 0.0,
    },
}


@pytest.fixture(scope="session")
def binary():
    """The command line built from this repository (built here when absent)."""
    path = pathlib.Path(os.environ.get("MOTORCAL_BIN", REPO / "target" / "release" / "motorcal"))
    if not path.exists():
        subprocess.run(
            ["cargo", "build", "--release", "--bin", "motorcal"], cwd=REPO, check=True
        )
    return path


@pytest.fixture(scope="session")
def model():
    return motorcal.Model.from_dict(NOMINAL)


@pytest.fixture(scope="session")
def recording():
    """201 samples of the paper's motor (c_g = 0.01) with the paper's noise."""
    return motorcal.simulate(seed=5, samples=201, t_end=0.5)


@pytest.fixture(scope="session")
def files(tmp_path_factory, model, recording):
    """The recording and the model as files, for the command line."""
    root = tmp_path_factory.mktemp("problem")
    recording.to_csv(root / "recording.csv")
    model.write(root / "motor.toml")
    return root / "recording.csv", root / "motor.toml"
