"""Recordings, models, the log density and its gradient, and the errors bad input raises."""

import numpy as np
import pytest

import motorcal


def test_the_gradient_equals_finite_differences(model, recording):
    posterior = motorcal.Posterior(recording, model, bm=2, k=3)
    theta = posterior.map()["x"] + 0.1 * posterior.map()["laplace_sd"]
    lp, grad = posterior.log_density_gradient(theta)
    assert lp == pytest.approx(posterior.log_density(theta), rel=1e-12)
    sd = posterior.map()["laplace_sd"]
    for i in range(posterior.dim):
        h = 1e-4 * sd[i]
        up, down = theta.copy(), theta.copy()
        up[i] += h
        down[i] -= h
        fd = (posterior.log_density(up) - posterior.log_density(down)) / (2 * h)
        # Relative to the gradient's own scale in the posterior's units: g·sd.
        assert abs(fd - grad[i]) * sd[i] < 1e-4 * max(1.0, abs(grad[i]) * sd[i]), (
            posterior.parameter_names[i],
            fd,
            grad[i],
        )


def test_the_module_functions_are_the_posteriors(model, recording):
    posterior = motorcal.Posterior(recording, model, bm=1)
    theta = posterior.initial_point()
    assert motorcal.log_density(model, recording, theta, bm=1) == posterior.log_density(theta)
    lp, grad = motorcal.log_density_gradient(model, [recording], theta, bm=1)
    lp2, grad2 = posterior.log_density_gradient(theta)
    assert lp == lp2 and np.array_equal(grad, grad2)
    assert posterior.parameter_names[:3] == ["R", "log_sigma_I", "log_sigma_omega"]
    assert posterior.output_names[:3] == ["R", "sigma_I", "sigma_omega"]


def test_a_csv_and_arrays_give_the_same_density(model, recording, files):
    csv = motorcal.Recording.from_csv(files[0])
    cols = recording.columns()
    arrays = motorcal.Recording.from_arrays(cols["t"], cols["I"], cols["omega"])
    theta = motorcal.Posterior(csv, model, bm=1).initial_point()
    values = {
        motorcal.log_density(model, r, theta, bm=1) for r in (recording, csv, arrays)
    }
    assert len(values) == 1, values
    assert len(csv) == 201
    assert np.array_equal(csv.t, recording.t)


def test_a_model_dict_round_trips(model):
    again = motorcal.Model.from_dict(model.to_dict())
    assert again.to_toml() == model.to_toml()
    assert model.base == "voltage_driven"


def test_bad_input_raises_value_error_naming_the_field(tmp_path, model, recording):
    cols = recording.columns()
    with pytest.raises(ValueError, match=r"field 't'.*does not increase"):
        motorcal.Recording.from_arrays(cols["t"][::-1], cols["I"], cols["omega"])
    with pytest.raises(ValueError, match=r"field 'omega'.*200 values, but t has 201"):
        motorcal.Recording.from_arrays(cols["t"], cols["I"], cols["omega"][1:])
    with pytest.raises(ValueError, match=r"field 'I'.*not a finite number"):
        bad = cols["I"].copy()
        bad[7] = np.nan
        motorcal.Recording.from_arrays(cols["t"], bad, cols["omega"])
    with pytest.raises(ValueError, match=r"field 'omega'.*no channel"):
        motorcal.Recording.from_arrays(cols["t"], cols["I"])
    csv = tmp_path / "bad.csv"
    csv.write_text("t,I,omega\n0,1,2\n0.1,x,3\n")
    with pytest.raises(ValueError, match=r"bad\.csv:3: field 'I'"):
        motorcal.Recording.from_csv(csv)
    toml = tmp_path / "bad.toml"
    toml.write_text("schema = 1\n[motor]\nR = -1.0\n")
    with pytest.raises(ValueError, match=r"bad\.toml:3: field 'motor\.R'"):
        motorcal.Model.from_toml(toml)
    with pytest.raises(ValueError, match=r"field 'motor\.Rr'"):
        motorcal.Model.from_dict({"schema": 1, "motor": {"Rr": 0.1}})
    with pytest.raises(ValueError, match=r"^theta = of length 2"):
        motorcal.log_density(model, recording, [0.0, 1.0], bm=1)
    with pytest.raises(ValueError, match=r"^sampler = nuts: expected one of"):
        motorcal.fit(recording, model, sampler="nuts")
    with pytest.raises(ValueError, match=r"^chains = 0: need at least one chain"):
        motorcal.fit(recording, model, chains=0)
