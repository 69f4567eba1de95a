"""rtid.run_experiment against `rtid experiment KIND`: the same manifest and the same
columns, every number to the bit (short runs of each test)."""

import json

import numpy as np
import pytest

import rtid
from rtid import _experiments


@pytest.mark.parametrize("kind, settings, flags", [
    ("frequency-response", dict(linear=True), ["--linear"]),
    ("frequency_response", dict(from_hz=150.0, to_hz=200.0, step_hz=25, refine_step_hz=0,
                                noise_percent=1.0, seed=3),
     ["--from-hz", 150, "--to-hz", 200, "--step-hz", 25, "--refine-step-hz", 0,
      "--noise-percent", 1, "--seed", 3]),
    ("torque-curve", dict(period_s=0.5, periods=1, noise_percent=1.0),
     ["--period-s", 0.5, "--periods", 1, "--noise-percent", 1]),
    ("unbalance", dict(speed_deg_per_min=3600, noise_arcsec=1.0, loop="full_closed"),
     ["--speed-deg-per-min", 3600, "--noise-arcsec", 1, "--loop", "full_closed"]),
    ("fluctuation", dict(speed_deg_per_min=7200, run_in_deg=5), ["--speed-deg-per-min", 7200,
                                                                 "--run-in-deg", 5]),
])
def test_run_experiment_is_the_cli_file(cli, tmp_path, kind, settings, flags):
    exp = rtid.run_experiment(kind, rtid.params("worm-gear"), **settings)
    cli("experiment", kind.replace("_", "-"), "--preset", "worm-gear", "--out", tmp_path, *flags)
    stem = kind.replace("-", "_")
    manifest = json.loads((tmp_path / f"{stem}.json").read_text())
    assert manifest.pop("data") == f"{stem}.csv"
    assert exp.manifest == manifest and exp.kind == stem
    columns = _experiments.read_columns(tmp_path / f"{stem}.csv")
    assert list(exp.columns) == list(columns)
    for name, values in columns.items():
        assert np.array_equal(exp.columns[name], values), name
    # And it is an experiment like any other (three noisy lines have no peaks to
    # evaluate).
    if len(columns[next(iter(columns))]) > 3:
        assert rtid.evaluate(exp)["kind"] == stem


@pytest.mark.parametrize("call, error, message", [
    (lambda p: rtid.run_experiment("torque-curv", p), ValueError, "did you mean `torque_curve`"),
    (lambda p: rtid.run_experiment("torque-curve", p, periode_s=1.0), ValueError, "did you mean `period_s`"),
    (lambda p: rtid.run_experiment("torque-curve", p, period_s="1"), TypeError, "period_s"),
    (lambda p: rtid.run_experiment("torque-curve", p, period_s=-1.0), ValueError, "period_s"),
    (lambda p: rtid.run_experiment("torque-curve", p, amplitude_mm=5.0), ValueError, "amplitude_mm"),
    (lambda p: rtid.run_experiment("unbalance", p, loop="ful_closed"), ValueError, "`full_closed`"),
    (lambda p: rtid.run_experiment("frequency-response", p, response="motor_compliance"), ValueError,
     "linear=True"),
])
def test_bad_settings_are_named(call, error, message):
    with pytest.raises(error, match=message):
        call(rtid.params("worm-gear"))
