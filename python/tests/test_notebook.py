"""What a notebook does with results: pickle them (and send them to other processes),
deep-copy them, read a fit's report, covariance and curves, tabulate with pandas."""

import concurrent.futures
import copy
import multiprocessing
import pickle

import numpy as np
import pytest

import rtid

WORM = "fixtures/worm-gear/frequency_response.json"


def linear_gain_experiment(kw: float) -> rtid.Experiment:
    """The worm gear's linear gain at Kw = `kw`, 100–300 Hz, as measured data."""
    p = rtid.params("worm-gear", Kw=kw)
    f = np.linspace(100.0, 300.0, 81)
    h = rtid.frequency_response(p, f)
    return rtid.experiment("frequency_response", frequency_hz=f, gain_db=20 * np.log10(np.abs(h)),
                           name=f"Kw={kw:g}")


@pytest.fixture(scope="module")
def worm_fit(root):
    return rtid.identify(root / WORM, rtid.params("worm-gear"), fit="Kw,Kg", model="linear")


def test_params_pickle_and_copy_to_the_bit():
    p = rtid.params("roller-gear-cam", Kw=1.2345678901234567e6)
    for q in (pickle.loads(pickle.dumps(p)), copy.deepcopy(p), copy.copy(p)):
        assert q == p and q is not p and q._inner is not p._inner
        assert q.to_json() == p.to_json() and dict(q) == dict(p) and q.name == p.name
    q = copy.deepcopy(p)
    q["Kw"] = 2e6
    assert p["Kw"] == 1.2345678901234567e6


def test_results_pickle_and_deep_copy(worm_fit, root):
    exp = linear_gain_experiment(3.1e5)
    s = rtid.sweep(rtid.params("worm-gear"), "Kw=1e5..1e6:log:3", "resonances")
    for obj in (exp, worm_fit, s, rtid.state_space(rtid.params("worm-gear"))):
        for twin in (pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj)):
            assert type(twin) is type(obj) and repr(twin) == repr(obj)
    recording = rtid.import_file(root / "fixtures/formats/matlab/DATA_EMPS.mat")
    twin = pickle.loads(pickle.dumps(recording))
    assert list(twin.channels) == list(recording.channels) and len(repr(twin)) < 200
    assert np.array_equal(twin.channels["vir"].samples, recording.channels["vir"].samples)
    fit = pickle.loads(pickle.dumps(worm_fit))
    assert fit.values == worm_fit.values and fit.params == worm_fit.params
    assert np.array_equal(fit.covariance, worm_fit.covariance)
    assert fit.report() == worm_fit.report()
    assert np.array_equal(fit.curves[0].residual, worm_fit.curves[0].residual)
    twin = pickle.loads(pickle.dumps(s))
    assert np.array_equal(twin.outputs, s.outputs) and twin.indices == s.indices


def test_identifications_run_one_per_process():
    # Experiments and parameter sets go to the workers pickled, results come back so.
    truths = [2.6e5, 3.6e5]
    start = rtid.params("worm-gear")
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=context) as pool:
        futures = [pool.submit(rtid.identify, linear_gain_experiment(kw), start, fit=["Kw"],
                               model="linear", starts=1) for kw in truths]
        fits = [f.result() for f in futures]
    for kw, fit in zip(truths, fits):
        assert isinstance(fit, rtid.IdentifyResult) and fit.success
        here = rtid.identify(linear_gain_experiment(kw), start, fit=["Kw"], model="linear", starts=1)
        assert fit.values == here.values and fit.params == here.params
        assert fit.values["Kw"] == pytest.approx(kw, rel=1e-2)  # peaks read on a 2.5 Hz grid


def test_the_report_has_every_parameter_its_correlations_and_warnings(worm_fit):
    text = worm_fit.report()
    for name, value in worm_fit.values.items():
        assert f"{name} = {value:.6g} ± {worm_fit.standard_errors[name]:.6g}" in text
    assert "[[Correlations]] (|r| > 0.1)" in text and "[[Warnings]]" in text
    assert f"chi-square         = {worm_fit.chisqr:.6g}" in text and worm_fit.chisqr == worm_fit.cost
    assert worm_fit.ndata == sum(len(r["residuals"]) for r in worm_fit.to_dict()["residuals"])
    assert worm_fit.redchi == pytest.approx(worm_fit.chisqr / (worm_fit.ndata - 2), rel=1e-15)
    n, k = worm_fit.ndata, worm_fit.nvarys
    assert worm_fit.aic == pytest.approx(n * np.log(worm_fit.chisqr / n) + 2 * k, rel=1e-12)
    assert worm_fit.bic == pytest.approx(n * np.log(worm_fit.chisqr / n) + k * np.log(n), rel=1e-12)
    for key in ("data points", "variables", "reduced chi-square", "Akaike info crit", "Bayesian info crit"):
        assert key in text
    r = abs(worm_fit.correlation[0, 1])
    assert (f"C({worm_fit.names[0]}, {worm_fit.names[1]})" in worm_fit.report(min_correl=r / 2))
    assert "none" in worm_fit.report(min_correl=min(r * 1.01, 1.0)).split("[[Correlations]]")[1]
    assert worm_fit.success and worm_fit.message
    assert repr(worm_fit).startswith("<rtid.IdentifyResult Kw=") and len(repr(worm_fit)) < 100


def test_the_covariance_is_the_standard_errors_times_the_correlation(worm_fit):
    se = np.array([worm_fit.standard_errors[n] for n in worm_fit.names])
    assert worm_fit.covariance.shape == (2, 2)
    assert np.allclose(np.sqrt(np.diag(worm_fit.covariance)), se, rtol=1e-12, atol=0)
    c01 = worm_fit.covariance[0, 1] / (se[0] * se[1])
    assert c01 == pytest.approx(worm_fit.correlation[0, 1], rel=1e-12)


def test_curves_are_the_data_beside_the_fitted_model(worm_fit, root):
    # The worm's record has phase: a gain curve and a phase curve.
    gain, phase = worm_fit.curves
    assert (gain.quantity, gain.unit, gain.abscissa_name, gain.abscissa_unit) == ("gain", "dB", "frequency", "Hz")
    assert gain.abscissa.size == gain.measured.size == gain.model.size > 20
    h = rtid.frequency_response(worm_fit.params, gain.abscissa)
    assert np.allclose(gain.model, 20 * np.log10(np.abs(h)), rtol=0, atol=1e-9)
    assert np.array_equal(gain.residual, gain.measured - gain.model)
    assert gain.model_start is not None and not np.array_equal(gain.model_start, gain.model)
    assert (phase.quantity, phase.unit) == ("phase", "deg")
    assert np.array_equal(phase.abscissa, gain.abscissa)
    # The model's phase is the linear response's, on the turn nearest the measured.
    turns = (phase.model - np.degrees(np.angle(h))) / 360.0
    assert np.allclose(turns, np.round(turns), atol=1e-9) and np.all(np.abs(phase.residual) <= 180.0)


def test_the_phase_curve_of_a_linear_measurement_is_its_noise():
    # 1 % complex noise is 0.01 rad, 0.57°, of phase: the fitted model's phase
    # differs from the measured by that alone. (The worm fixture above is the
    # nonlinear test, whose phase the linear model misses by up to 27° above the
    # resonances: backlash and friction.)
    truth = rtid.params("worm-gear")
    measured = rtid.run_experiment("frequency-response", truth, linear=True, from_hz=50.0, to_hz=400.0,
                                   step_hz=2.0, complex_noise_percent=1.0)
    fit = rtid.identify(measured, rtid.params("worm-gear", Kw=0.6 * truth["Kw"]), fit=["Kw"], model="linear")
    gain, phase = fit.curves
    assert phase.abscissa.size == gain.abscissa.size == measured.columns["frequency_hz"].size
    rms = np.sqrt(np.mean(phase.residual ** 2))
    assert 0.3 < rms < 0.9, rms


def test_tables_for_pandas_and_html(worm_fit):
    pd = pytest.importorskip("pandas")
    table = worm_fit.to_pandas()
    # One order everywhere: the table's rows label the covariance's rows and columns.
    assert list(table.index) == list(worm_fit.values) == worm_fit.names == list(worm_fit.standard_errors)
    cov = worm_fit.to_pandas("covariance")
    assert list(cov.index) == list(cov.columns) == list(table.index)
    assert np.allclose(np.sqrt(np.diag(cov.to_numpy())), table["stderr"].to_numpy(), rtol=1e-12, atol=0)
    corr = worm_fit.to_pandas("correlation")
    assert corr.loc["Kw", "Kg"] == worm_fit.correlation[0, 1] and corr.loc["Kw", "Kw"] == 1.0
    with pytest.raises(ValueError, match="did you mean `covariance`"):
        worm_fit.to_pandas("covariances")
    assert table.loc["Kw", "value"] == worm_fit.values["Kw"] and table.loc["Kw", "unit"] == "N·m/rad"
    assert table.loc["Kw", "lower"] < worm_fit.values["Kw"] < table.loc["Kw", "upper"]
    html = worm_fit._repr_html_()
    assert html.count("<tr>") == 1 + len(worm_fit.values) and "N·m/rad" in html
    s = rtid.sweep(rtid.params("worm-gear"), ["Kw", "Kg"], "resonances", method="local")
    frame = s.to_pandas()
    assert list(frame.columns) == s.factors + s.output_columns and len(frame) == len(s.index)
    long = s.indices_to_pandas()
    assert list(long.columns) == ["parameter", "output", "statistic", "value"]
    assert len(long) == len(s.indices["rows"]) * len(s.indices["columns"])
    row = long[(long.parameter == "Kw") & (long.output == "resonance_1_hz")]
    assert row.value.item() == pytest.approx(0.194, abs=1e-3)
    assert isinstance(frame, pd.DataFrame)
    assert "points of Kw, Kg" in repr(s) and len(repr(s)) < 120


def test_without_pandas_the_tables_say_what_is_missing(worm_fit, monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_pandas(name, *args, **kwargs):
        if name == "pandas":
            raise ImportError("No module named 'pandas'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_pandas)
    with pytest.raises(ImportError, match="to_pandas.*needs pandas.*pip install pandas"):
        worm_fit.to_pandas()


def test_progress_reaches_a_function_and_a_tqdm_bar(root):
    calls = []
    worm = root / WORM
    fit = rtid.identify(worm, rtid.params("worm-gear"), fit="Kw,Kg", model="linear",
                        progress=lambda *counts: calls.append(counts))
    assert fit.success and calls and all(len(c) == 3 for c in calls)
    done, budget, evaluations = calls[-1]
    assert 0 <= done <= budget and evaluations >= 0
    rows = []
    s = rtid.sweep(rtid.params("worm-gear"), "Kw=1e5..1e6:log:5", "resonances", progress=lambda *c: rows.append(c))
    assert all(total == len(s.index) and 0 <= n <= total for n, total in rows)

    def refuse(*counts):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        rtid.identify(worm, rtid.params("worm-gear"), fit="Kw,Kg", model="linear", progress=refuse)
    pytest.importorskip("tqdm")
    assert rtid.identify(worm, rtid.params("worm-gear"), fit="Kw,Kg", model="linear",
                         progress=True).values == fit.values


def test_an_undetermined_standard_error_is_nan_not_a_missing_key():
    # The linear response has no friction: fm has no effect on it, and the fit's
    # Jacobian is singular — rtid warns and gives no standard errors.
    truth = rtid.params("worm-gear")
    measured = rtid.run_experiment("frequency-response", truth, linear=True, from_hz=50.0, to_hz=400.0,
                                   step_hz=5.0)
    fit = rtid.identify(measured, truth, fit="Kw,fm", model="linear")
    assert {w["code"] for w in fit.warnings} >= {"no_effect", "singular"}
    assert list(fit.standard_errors) == fit.names == ["Kw", "fm"]
    assert all(np.isnan(se) for se in fit.standard_errors.values())
    assert "fm = " in fit.report() and "(not determined)" in fit.report()
    assert np.isnan(fit.covariance).all()
    pytest.importorskip("pandas")
    assert fit.to_pandas()["stderr"].isna().all()
