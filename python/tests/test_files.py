"""rtid.import_file, rtid.evaluate and rtid.sweep against `rtid import --list`,
`rtid evaluate --json` and `rtid sweep`'s CSV and indices."""

import csv

import numpy as np
import pytest

import rtid

MAT = "fixtures/formats/matlab/DATA_EMPS.mat"


def test_import_gives_the_cli_channels(cli, root):
    rec = rtid.import_file(root / MAT)
    listed = cli("import", MAT, "--list", "--json", json_out=True)["channels"]
    assert list(rec.channels) == [c["name"] for c in listed]
    for c in listed:
        ch = rec.channels[c["name"]]
        assert ch.samples.dtype == np.float64 and ch.samples.shape == (c["samples"],)
        assert ch.unit == c["unit"]
        assert (ch.samples[0], ch.samples[-1]) == (c["first"], c["last"])
    assert rec.format == "matlab-v5"


def test_import_of_a_missing_file_names_the_path(tmp_path):
    with pytest.raises(ValueError, match="path"):
        rtid.import_file(tmp_path / "none.mat")


@pytest.mark.parametrize("manifest", [
    "fixtures/real/emps/emps_estimation.json",
    "fixtures/worm-gear/frequency_response.json",
    "fixtures/frf/worm_frf.json",
    "fixtures/worm-gear/torque_curve.json",
    "fixtures/compensate/worm-gear/positioning.json",
    "fixtures/worm-gear/unbalance.json",
])
def test_evaluate_gives_the_cli_evaluation(cli, root, manifest):
    expected = cli("evaluate", manifest, "--json", json_out=True)
    got = rtid.evaluate(root / manifest)
    expected.pop("source")
    got.pop("source")
    assert got == expected


def test_evaluate_of_a_friction_map_is_the_cli_evaluation(cli, tmp_path):
    cli("experiment", "friction-map", "--preset", "two-mass", "--out", tmp_path)
    manifest = tmp_path / "friction_map.json"
    expected = cli("evaluate", manifest, "--json", json_out=True)
    got = rtid.evaluate(manifest)
    assert got == expected  # the source too: the path as given


def test_evaluate_of_a_linear_axis_torque_curve_is_in_newtons_as_the_cli(cli, root, tmp_path):
    axis = root / "fixtures/real/emps/axis.json"
    cli("experiment", "torque-curve", "--params", axis, "--periods", "1", "--out", tmp_path)
    manifest = tmp_path / "torque_curve.json"
    expected = cli("evaluate", manifest, "--json", json_out=True)
    got = rtid.evaluate(manifest)
    assert "rms_n" in got and "rms_nm" not in got
    assert got == expected


def test_evaluate_of_a_servo_trace_on_a_model_is_the_cli_replay(cli, root):
    manifest, axis = "fixtures/real/emps/emps_estimation.json", "fixtures/real/emps/axis.json"
    expected = cli("evaluate", manifest, "--params", axis, "--json", json_out=True)
    got = rtid.evaluate(root / manifest, params=rtid.params(path=root / axis))
    expected.pop("source")
    got.pop("source")
    assert got["simulation_error"]["position_rms"] > 0
    assert got == expected
    with pytest.raises(ValueError, match="axis"):
        rtid.evaluate(root / manifest, params=rtid.params("worm-gear"))


def test_evaluate_of_a_measured_multisine_is_the_cli_s(cli, root):
    # A raw time record (the two-mass bench's periodic multisine, docs/multisine.md).
    path = "fixtures/real/two-mass/multisine_a.json"
    shown = cli("evaluate", path, "--json", json_out=True)
    mine = rtid.evaluate(root / path)
    shown.pop("source")
    mine.pop("source")
    assert mine == shown
    assert mine["motor_resonances_hz"] and mine["motor_antiresonances_hz"]


def read_rows(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    return rows[0], rows[1:]


def test_sweep_gives_the_cli_file_and_indices(cli, root, tmp_path):
    out = tmp_path / "s.csv"
    cli("sweep", "--preset", "worm-gear", "--method", "local", "--vary", "Kw", "--vary", "Kg",
        "--outputs", "resonances", "--out", out)
    s = rtid.sweep(rtid.params("worm-gear"), ["Kw", "Kg"], ["resonances"], method="local")
    header, rows = read_rows(out)
    assert s.factors == ["Kw", "Kg"] and s.design.shape == (len(rows), 2) and s.design.dtype == np.float64
    assert s.outputs.shape == (len(rows), len(s.output_columns))
    k = len(s.factors)
    assert [h.split("_")[0] for h in header[1:1 + k]] == s.factors
    assert header[1 + k:1 + k + len(s.output_columns)] == s.output_columns
    assert np.array_equal(s.index, [int(r[0]) for r in rows])
    assert np.array_equal(s.design, [[float(v) for v in r[1:1 + k]] for r in rows])
    assert np.array_equal(s.outputs, [[float(v) for v in r[1 + k:1 + k + len(s.output_columns)]] for r in rows])
    ih, irows = read_rows(tmp_path / "s-indices.csv")
    assert len(irows) == len(s.indices["rows"]) == k * len(s.output_columns)
    first = s.indices["rows"][0]
    value = float(irows[0][ih.index(s.indices["columns"][0])])
    assert first["values"][0] == pytest.approx(value, rel=1e-9)


def test_sweep_options_are_checked():
    p = rtid.params("worm-gear")
    with pytest.raises(ValueError, match="vary"):
        rtid.sweep(p, [], ["resonances"])
    with pytest.raises(ValueError, match="outputs"):
        rtid.sweep(p, ["Kw=1e5..1e6"], ["resonance_count"])
    with pytest.raises(ValueError, match="method"):
        rtid.sweep(p, ["Kw=1e5..1e6"], ["resonances"], method="fast")
