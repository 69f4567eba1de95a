"""The whole command line from Python, each against the `rtid` binary on the same
inputs: the virtual tests the module runs since issue 59 (positioning with a
compensation and a tuned controller, the friction map, the servo trace, the raw time
record and its evaluation), compensate, tune, predict, select, and an identification
interrupted with a checkpoint and resumed."""

import json
import math
import pickle

import numpy as np
import pytest

import rtid

EMPS = "fixtures/real/emps/emps_estimation.json"
AXIS = "fixtures/real/emps/axis.json"
WORM = "fixtures/worm-gear/frequency_response.json"


def columns_of(manifest_path):
    """An experiment file's columns as rtid.read_experiment … evaluate see them."""
    with open(manifest_path, encoding="utf-8") as f:
        manifest = json.load(f)
    from rtid import _experiments

    return manifest, _experiments.read_columns(str(manifest_path.parent / manifest["data"]))


def assert_same_experiment(exp, manifest_path):
    """The Python experiment is the file the command line wrote, to the bit."""
    manifest, columns = columns_of(manifest_path)
    manifest.pop("data")
    assert exp.manifest == manifest
    assert list(exp.columns) == list(columns)
    for name, column in columns.items():
        assert np.array_equal(exp.columns[name], column), name


def close(a, b, rel=1e-9):
    """Two JSON values equal, their numbers to `rel`."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (sorted(a), sorted(b))
        for k in a:
            close(a[k], b[k], rel)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b)
        for x, y in zip(a, b):
            close(x, y, rel)
    elif isinstance(a, float) and isinstance(b, (int, float)):
        assert b == pytest.approx(a, rel=rel, abs=1e-12), (a, b)
    else:
        assert a == b, (a, b)


@pytest.fixture(scope="module")
def drive():
    return rtid.params("direct-drive")


@pytest.fixture(scope="module")
def positioning(cli, tmp_path_factory, drive):
    """The direct drive's ISO 230-2 test, 3 runs, by the command line and from Python."""
    out = tmp_path_factory.mktemp("positioning")
    iso = cli("experiment", "positioning", "--preset", "direct-drive", "--runs", "4",
              "--noise-arcsec", "0.3", "--seed", "4", "--out", out, "--json", json_out=True)
    exp = rtid.run_experiment("positioning", drive, runs=4, noise_arcsec=0.3, seed=4)
    return out, iso, exp


def test_the_positioning_test_is_the_cli_s_to_the_bit(positioning):
    out, iso, exp = positioning
    assert_same_experiment(exp, out / "positioning.json")
    mine = rtid.evaluate(exp)
    for key, value in iso["axis"].items():
        assert mine["axis"][key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
    close(iso["targets"], mine["targets"])
    # The record from its arrays (the directions as words): the same evaluation.
    again = rtid.experiment("positioning", **exp.columns)
    assert rtid.evaluate(again) == dict(mine, source=again.name)


def test_compensate_gives_the_cli_s_compensation_and_it_runs_in_the_controller(cli, positioning, drive, tmp_path):
    out, _, exp = positioning
    comp_file = tmp_path / "compensation.json"
    summary = cli("compensate", out / "positioning.json", "--runs", "1-2", "-o", comp_file, "--json",
                  json_out=True)
    c = rtid.compensate(exp, runs="1-2")
    assert c.to_dict()["table"] == json.loads(comp_file.read_text())["table"]
    assert c.to_dict()["backlash"] == json.loads(comp_file.read_text())["backlash"]
    summary.pop("source")
    mine = dict(c.summary)
    mine.pop("source")
    close(summary, mine, rel=1e-12)
    assert c.summary["build_runs"] == [1, 2] and c.summary["check_runs"] == [3, 4]
    twin = pickle.loads(pickle.dumps(c))
    assert twin.text == c.text and twin.summary == c.summary and repr(twin) == repr(c)
    # Its effect on the record, and run in the model's controller.
    shown = cli("evaluate", out / "positioning.json", "--runs", "3-4", "--compensation", comp_file, "--json",
                json_out=True)
    mine = rtid.evaluate(exp, runs="3-4", compensation=c)
    for key in ("uncompensated", "backlash_only", "compensated"):
        close(shown[key], mine[key])
    run_dir = tmp_path / "compensated"
    iso = cli("experiment", "positioning", "--preset", "direct-drive", "--runs", "2", "--compensation", comp_file,
              "--out", run_dir, "--json", json_out=True)
    compensated = rtid.run_experiment("positioning", drive, runs=2, compensation=c)
    assert_same_experiment(compensated, run_dir / "positioning.json")
    close(iso["axis"], rtid.evaluate(compensated)["axis"])
    # Its SINUMERIK program and CSV: the command line's numbers.
    program = tmp_path / "AX4_EEC.SPF"
    table = tmp_path / "table.csv"
    cli("compensate", out / "positioning.json", "--runs", "1-2", "--sinumerik", program, "--axis-number", "4",
        "--csv", table)
    numbers = lambda text: [line for line in text.splitlines() if not line.startswith(";")]  # noqa: E731
    assert numbers(c.sinumerik(4)) == numbers(program.read_text())
    assert c.csv() == table.read_text()


def test_a_compensation_of_the_model_is_the_cli_s(cli, drive):
    summary = cli("compensate", "--preset", "direct-drive", "--friction", "--json", json_out=True)
    c = rtid.compensate(drive, friction=True)
    summary.pop("source")
    mine = dict(c.summary)
    mine.pop("source")
    close(summary, mine, rel=1e-12)
    assert c.to_dict()["friction"]["coulomb"] > 0


def test_tune_is_the_cli_s(cli, drive, tmp_path):
    sinamics = tmp_path / "sinamics.txt"
    tuned_file = tmp_path / "tuned.json"
    shown = cli("tune", "--preset", "direct-drive", "-o", tuned_file, "--sinamics", sinamics, "--json",
                json_out=True)
    t = rtid.tune(drive, progress=False)
    for key in ("before", "after", "proposes", "targets", "loop", "objective", "warnings", "check",
                "resonances", "candidates", "range"):
        close(shown[key], t.summary[key], rel=1e-12)
    assert t.params == rtid.params(path=tuned_file)
    assert t.sinamics() == sinamics.read_text()
    # The default range: the preset's held ranges that move today's margins.
    varied = [v["name"] for v in t.summary["range"]["vary"]]
    assert "Jt" in varied and "ft" not in varied, t.summary["range"]


def test_a_tunings_range_is_checked_before_it_runs(drive):
    with pytest.raises(rtid.RtidError, match="vary: Jt"):
        rtid.tune(drive, vary={"Jt": (0.5,)}, progress=False)
    with pytest.raises(rtid.RtidError, match="delay_periods"):
        rtid.tune(drive, delay_periods=-1, progress=False)
    with pytest.raises(rtid.RtidError, match="nominal"):
        rtid.tune(drive, nominal=True, vary={"Jt": (0.5, 2)}, progress=False)
    with pytest.raises(rtid.RtidError, match="Jt"):
        rtid.tune(drive, vary={"Jt": (2, 0.5)}, progress=False)


def test_a_tuned_controller_runs_in_the_tests_as_the_cli_s_tune_file(cli, tmp_path):
    # Params carry the controller: gains, filters, loop — a set saved as `rtid tune
    # -o` writes it, given to the command line's --tune and to with_controller.
    worm = rtid.params("worm-gear")
    tuned = worm.copy()
    tuned["Kvp"] = 0.8 * worm["Kvp"]
    tuned.filters = [{"type": "notch", "centre_hz": 194.0, "width_hz": 40.0, "depth_db": -20.0}]
    tuned.loop = "full_closed"
    tuned_file = tmp_path / "tuned.json"
    tuned.save(tuned_file)
    run_dir = tmp_path / "tuned"
    iso = cli("experiment", "positioning", "--preset", "worm-gear", "--runs", "2", "--target-step-deg", "90",
              "--tune", tuned_file, "--out", run_dir, "--json", json_out=True)
    model = worm.with_controller(rtid.params(path=tuned_file))
    assert model["Kvp"] == tuned["Kvp"] and model.filters == tuned.filters and model.loop == "full_closed"
    exp = rtid.run_experiment("positioning", model, runs=2, target_step_deg=90)
    assert_same_experiment(exp, run_dir / "positioning.json")
    close(iso["axis"], rtid.evaluate(exp)["axis"])
    plain = rtid.evaluate(rtid.run_experiment("positioning", worm, runs=2, target_step_deg=90))["axis"]
    # Full-closed on the table encoder: the backlash no longer shows.
    assert iso["axis"]["B"] < 0.2 * plain["B"]


def test_predict_is_the_cli_s(cli, tmp_path, drive):
    # The direct drive identified from its own servo trace, its friction compensated:
    # the positioning test and the servo's check before and after, 10 draws.
    cli("experiment", "servo-trace", "--preset", "direct-drive", "--out", tmp_path)
    fit = tmp_path / "fit.json"
    cli("identify", tmp_path / "servo_trace.json", "--preset", "direct-drive", "--out", fit)
    comp_file = tmp_path / "compensation.json"
    cli("compensate", "--fit", fit, "--preset", "direct-drive", "--friction", "-o", comp_file)
    shown = cli("predict", fit, "--preset", "direct-drive", "--compensation", comp_file, "--tests",
                "positioning,servo", "--draws", "10", "--runs", "2", "--json", json_out=True)
    p = rtid.predict(fit, drive, compensation=comp_file, tests="positioning,servo", draws=10, runs=2)
    close(shown, p.to_dict(), rel=1e-12)
    # From Python end to end: the same fit from the same trace, the same compensation
    # (so the same prediction from them).
    python_fit = rtid.identify(rtid.run_experiment("servo_trace", drive), drive, progress=False)
    cli_fit = json.loads(fit.read_text())
    assert python_fit.values == pytest.approx(cli_fit["parameters"], rel=1e-12)
    c = rtid.compensate(python_fit.params, friction=True)
    close(c.to_dict()["friction"], json.loads(comp_file.read_text())["friction"], rel=1e-12)
    assert p.completed == p.asked and {c["test"] for c in p.cases} == {"positioning", "servo"}


def test_the_friction_map_servo_trace_and_time_record_are_the_cli_s(cli, tmp_path, drive):
    out = tmp_path / "map"
    cli("experiment", "friction-map", "--preset", "direct-drive", "--speeds-rpm", "5,50", "--average-s", "0.5",
        "--noise-percent", "1", "--scatter-percent", "1", "--out", out)
    m = rtid.run_experiment("friction_map", drive, speeds_rpm=[5, 50], average_s=0.5, noise_percent=1.0,
                            scatter_percent=1.0)
    assert_same_experiment(m, out / "friction_map.json")
    out = tmp_path / "trace"
    cli("experiment", "servo-trace", "--preset", "direct-drive", "--moves", "0.2@0.5,0@0.25", "--out", out)
    t = rtid.run_experiment("servo_trace", drive, moves="0.2@0.5,0@0.25")
    assert_same_experiment(t, out / "servo_trace.json")
    assert_same_experiment(rtid.run_experiment("servo_trace", drive, moves=[(0.2, 0.5), (0.0, 0.25)]),
                           out / "servo_trace.json")
    out = tmp_path / "record"
    shown = cli("experiment", "frequency-response-time", "--preset", "worm-gear", "--duration-s", "2",
                "--to-hz", "400", "--segment-s", "0.25", "--out", out, "--json", json_out=True)
    r = rtid.run_experiment("frequency_response_time", rtid.params("worm-gear"), duration_s=2.0, to_hz=400.0)
    assert_same_experiment(r, out / "frequency_response_time.json")
    mine = rtid.evaluate(r, segment_s=0.25)
    shown.pop("source")
    mine.pop("source")
    close(shown, mine, rel=1e-12)
    assert mine["kind"] == "frequency_response_time" and "peaks" in mine


def test_select_is_the_cli_s(cli, root, tmp_path):
    small, big = tmp_path / "kw-kg.json", tmp_path / "kw-kg-cig.json"
    cli("identify", WORM, "--preset", "worm-gear", "--model", "linear", "--fit", "Kw,Kg", "--out", small)
    cli("identify", WORM, "--preset", "worm-gear", "--model", "linear", "--fit", "Kw,Kg,Cig", "--out", big)
    shown = cli("select", small, big, "--json", json_out=True)
    start = rtid.params("worm-gear")
    fits = [rtid.identify(root / WORM, start, fit=f, model="linear") for f in ("Kw,Kg", "Kw,Kg,Cig")]
    mine = rtid.select(*fits, labels=[str(small), str(big)])
    close(shown, mine, rel=1e-9)
    assert rtid.select(small, big) == shown
    # The report's AIC is select's.
    by_label = {c["label"]: c for c in mine["candidates"]}
    assert fits[0].aic == pytest.approx(by_label[str(small)]["aic"], rel=1e-12)


def test_an_identification_interrupted_with_a_checkpoint_resumes_to_the_same_result(root, tmp_path):
    checkpoint = tmp_path / "fit.ck.json"
    whole = rtid.identify(root / EMPS, rtid.params(path=root / AXIS), progress=False)

    def ctrl_c(done, budget, evaluations):
        # Once the search has a point to keep (before it, Ctrl-C is just that).
        if evaluations > 0:
            raise KeyboardInterrupt

    with pytest.warns(RuntimeWarning, match="interrupted"):
        stopped = rtid.identify(root / EMPS, rtid.params(path=root / AXIS), checkpoint=checkpoint,
                                progress=ctrl_c)
    assert stopped.interrupted and checkpoint.exists()
    resumed = rtid.identify(root / EMPS, rtid.params(path=root / AXIS), checkpoint=checkpoint, resume=True,
                            progress=False)
    assert not resumed.interrupted
    for name, value in whole.values.items():
        assert resumed.values[name] == pytest.approx(value, rel=1e-12), name
    assert resumed.cost == pytest.approx(whole.cost, rel=1e-12)
    with pytest.raises(ValueError, match="resume: give checkpoint="):
        rtid.identify(root / EMPS, rtid.params(path=root / AXIS), resume=True)


def test_params_carry_the_loop_and_the_filters(tmp_path):
    p = rtid.params("worm-gear")
    assert p.loop == "semi_closed" and p.filters == []
    p.loop = "full_closed"
    p.filters = [{"type": "notch", "centre_hz": 480.0, "width_hz": 96.0, "depth_db": -20.0},
                 {"type": "low_pass", "frequency_hz": 900.0, "damping": 0.7}]
    p.save(tmp_path / "p.json")
    q = rtid.params(path=tmp_path / "p.json")
    assert q.loop == "full_closed" and q.filters == p.filters
    with pytest.raises(ValueError, match="loop"):
        p.loop = "open"
    with pytest.raises(ValueError, match="filters"):
        p.filters = [{"type": "notch", "centre_hz": 480.0}]
    with pytest.raises(TypeError, match=r"filters\[0\]"):
        p.filters = ["notch"]
    with pytest.raises(ValueError, match="tuned"):
        p.with_controller(rtid.params("direct-drive"))
    assert math.isfinite(p["Kvp"])
