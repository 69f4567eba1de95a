"""rtid.identify against `rtid identify --out` on the EMPS benchmark's record: from
the manifest, from arrays, from the MAT-file through scipy — the CLI's parameters to
1e-12 — and Ctrl-C keeping the best point."""

import json
import math
import os
import signal
import threading
import warnings

import numpy as np
import pytest
import scipy.io

import rtid

EMPS = "fixtures/real/emps/emps_estimation.json"
AXIS = "fixtures/real/emps/axis.json"
CONDITIONS = {"drive_gain": 35.15065188248547, "loop_period_s": 0.001}


@pytest.fixture(scope="module")
def cli_fit(cli, root, tmp_path_factory):
    out = tmp_path_factory.mktemp("fit") / "emps-fit.json"
    cli("identify", EMPS, "--params", AXIS, "--out", out)
    return json.loads(out.read_text())


def assert_cli_parameters(result, cli_fit):
    assert set(result.values) == set(cli_fit["parameters"])
    for name, expected in cli_fit["parameters"].items():
        assert result.values[name] == pytest.approx(expected, rel=1e-12, abs=0), name
    errors = dict(cli_fit["uncertainty"]["standard_errors"])
    for name, expected in errors.items():
        assert result.standard_errors[name] == pytest.approx(expected, rel=1e-12, abs=0), name


def test_identify_from_the_manifest_is_the_cli_fit(root, cli_fit):
    result = rtid.identify(root / EMPS, rtid.params(path=root / AXIS))
    assert_cli_parameters(result, cli_fit)
    names = cli_fit["uncertainty"]["names"]
    assert result.names == names
    assert result.correlation.dtype == np.float64 and result.correlation.shape == (len(names), len(names))
    assert np.array_equal(result.correlation, np.array(cli_fit["uncertainty"]["correlation"]))
    assert [w["code"] for w in result.warnings] == [w["code"] for w in cli_fit["warnings"]]
    assert not result.interrupted
    for name, (lo, hi) in result.intervals.items():
        assert lo < result.values[name] < hi
    d = result.to_dict()
    assert d["parameters"] == result.values and d["evaluations"] == cli_fit["evaluations"]
    for name, value in result.values.items():
        assert result.params[name] == value


def test_identify_from_arrays_is_the_cli_fit(root, cli_fit):
    table = np.loadtxt(root / "fixtures/real/emps/emps_estimation.csv", delimiter=",", skiprows=3)
    t, qm, qg, vir, force = table.T
    exp = rtid.experiment("servo_trace", conditions=CONDITIONS, time_s=t, motor_position_m=qm,
                          reference_position_m=qg, controller_output_v=vir, force_n=force)
    result = rtid.identify([exp], rtid.params(path=root / AXIS))
    assert_cli_parameters(result, cli_fit)


def test_identify_from_the_mat_file_through_scipy_is_the_cli_fit(root, cli_fit):
    mat = scipy.io.loadmat(root / "fixtures/formats/matlab/DATA_EMPS.mat")
    gtau = mat["gtau"].item()
    vir = mat["vir"].ravel()
    exp = rtid.experiment("servo_trace", conditions={"drive_gain": gtau, "loop_period_s": 0.001},
                          time_s=mat["t"].ravel(), motor_position_m=mat["qm"].ravel(),
                          reference_position_m=mat["qg"].ravel(), controller_output_v=vir,
                          force_n=gtau * vir)
    assert_cli_parameters(rtid.identify(exp, rtid.params(path=root / AXIS)), cli_fit)


def test_ctrl_c_ends_the_search_with_the_best_point(root):
    # A search of minutes (Nelder–Mead, each evaluation a replay of the whole
    # trace), interrupted 0.3 s after it reports its first progress, as a notebook's
    # interrupt would. (The timer starts there, not before the call: an interrupt
    # while Python still prepares the call is Python's KeyboardInterrupt.) The
    # warnings are recorded rather than asserted with pytest.warns, so that an
    # exception from the call is reported as itself. Python's own SIGINT handler is
    # installed for the test: a shell that starts a job in the background without
    # job control has it ignore SIGINT, and Python then leaves it ignored (a
    # notebook's kernel has the handler).
    budget = 5000
    timers = []
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)

    def progress(done, total, evaluations):
        if not timers:
            timers.append(threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT)))
            timers[0].start()

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = rtid.identify(root / EMPS, rtid.params(path=root / AXIS),
                                   method="nelder-mead", max_iters=budget, progress=progress)
    finally:
        for t in timers:
            t.cancel()
        signal.signal(signal.SIGINT, inherited)
    assert timers, "the search reported no progress"
    assert any(issubclass(w.category, RuntimeWarning) and "interrupted" in str(w.message)
               for w in caught), [str(w.message) for w in caught]
    assert result.interrupted
    assert result.to_dict()["evaluations"] < budget
    assert all(math.isfinite(v) for v in result.values.values())
    assert result.params["Jt"] == result.values["Jt"]


@pytest.mark.parametrize("kwargs, argument", [
    (dict(fit=["Jt", "Kx"]), "Kx"),
    (dict(fit=["Jt"], bounds={"Jt": (1.0, float("nan"))}), "bounds"),
    (dict(method="newton"), "method"),
    (dict(model="exact"), "model"),
    (dict(starts=0), "starts"),
    (dict(weights=[1.0, 2.0]), "weights"),
    (dict(objectives=["resonance"]), "objectives"),
])
def test_bad_options_raise_value_error_naming_them(root, kwargs, argument):
    with pytest.raises(ValueError, match=argument):
        rtid.identify(root / EMPS, rtid.params(path=root / AXIS), **kwargs)


@pytest.mark.parametrize("columns, argument", [
    (dict(force_n=np.array([1.0, np.nan, 3.0])), r"force_n\[1\]"),
    (dict(force_n=np.zeros(3), time_s=np.zeros(4)), "time_s"),
    (dict(force_n=[[1.0, 2.0]]), "force_n: 2-dimensional"),
])
def test_bad_arrays_raise_value_error_naming_the_column(columns, argument):
    with pytest.raises(ValueError, match=argument):
        rtid.experiment("servo_trace", conditions=CONDITIONS, **columns)


def test_a_column_of_strings_raises_type_error_naming_it():
    with pytest.raises(TypeError, match="force_n: dtype"):
        rtid.experiment("servo_trace", conditions=CONDITIONS, force_n=np.array(["1", "2"]))


def test_a_missing_column_is_named_by_rtid_reader():
    with pytest.raises(ValueError, match="missing column"):
        rtid.experiment("servo_trace", conditions=CONDITIONS, time_s=np.arange(5) * 1e-3,
                        force_n=np.zeros(5))


def test_profile_and_resample_give_the_cli_intervals(cli, root, tmp_path):
    worm = root / "fixtures/worm-gear/frequency_response.json"
    out = tmp_path / "fit.json"
    cli("identify", worm, "--preset", "worm-gear", "--fit", "Kw,Kg", "--model", "linear",
        "--profile", "Kw", "--resample", "5", "--out", out)
    expected = json.loads(out.read_text())
    p = rtid.params("worm-gear")
    profiled = rtid.identify(worm, p, fit="Kw,Kg", model="linear", profile=["Kw"])
    assert profiled.interval_method == "profile"
    lower, upper = profiled.intervals["Kw"]
    assert lower == pytest.approx(expected["profiles"]["Kw"]["lower"], rel=1e-12, abs=0)
    assert upper == pytest.approx(expected["profiles"]["Kw"]["upper"], rel=1e-12, abs=0)
    boot = rtid.identify(worm, p, fit="Kw,Kg", model="linear", resample=5)
    assert boot.interval_method == "bootstrap"
    for name, i in expected["resampling"]["intervals"].items():
        assert boot.intervals[name] == pytest.approx((i["lower"], i["upper"]), rel=1e-12, abs=0)
    assert rtid.identify(worm, p, fit="Kw,Kg", model="linear").interval_method == "standard errors"


def test_held_ranges_give_the_cli_shifts(cli, root, tmp_path):
    worm = root / "fixtures/worm-gear/frequency_response.json"
    out = tmp_path / "fit.json"
    cli("identify", worm, "--preset", "worm-gear", "--fit", "Kw,Kg", "--model", "linear",
        "--uncertain", "Jt=10%", "--out", out)
    expected = json.loads(out.read_text())["held"]
    r = rtid.identify(worm, rtid.params("worm-gear"), fit="Kw,Kg", model="linear",
                      uncertain={"Jt": 0.1})
    # The preset's own held ranges are carried beside Jt's, by both.
    assert [h["name"] for h in r.held] == [h["name"] for h in expected]
    assert "Jw" in [h["name"] for h in r.held]
    for mine, theirs in zip(r.held, expected):
        assert mine["half_width"] == theirs["half_width"]
        for name, shift in theirs["shifts"].items():
            assert mine["shifts"][name] == pytest.approx(shift, rel=1e-12, abs=0)
    jt = next(h for h in r.held if h["name"] == "Jt")
    assert jt["half_width"] == 0.1
    exact = rtid.identify(worm, rtid.params("worm-gear"), fit="Kw,Kg", model="linear",
                          uncertain={"Jt": 0})
    assert "Jt" not in [h["name"] for h in exact.held]


@pytest.mark.parametrize("kwargs, argument", [
    ({"resample": 0}, "resample"),
    ({"uncertain": {"Jt": 1.5}}, "uncertain"),
    ({"uncertain": {"Jtt": 0.1}}, "uncertain"),
    ({"profile": [""]}, "profile"),
])
def test_bad_interval_options_name_themselves(root, kwargs, argument):
    worm = root / "fixtures/worm-gear/frequency_response.json"
    with pytest.raises(ValueError, match=argument):
        rtid.identify(worm, rtid.params("worm-gear"), fit="Kw", model="linear", **kwargs)
