"""rtid.simulate against `rtid simulate`'s CSV: the same columns and, rounded as the
CSV writes them, the same numbers."""

import csv

import numpy as np
import pytest

import rtid

# How the CLI writes each column (src/cli/model/simulate.rs): time fixed to 9
# decimals, the torque with 9 significant decimals, the states with 12.
FORMATS = {"time_s": "{:.9f}", "motor_torque_nm": "{:.9e}"}


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return header, {name: np.array([float(r[i]) for r in body]) for i, name in enumerate(header)}


def rounded(name, values):
    fmt = FORMATS.get(name, "{:.12e}")
    return np.array([float(fmt.format(v)) for v in values])


def assert_as_cli(run, path):
    header, columns = read_csv(path)
    assert list(run) == header
    for name in header:
        assert run[name].dtype == np.float64 and run[name].shape == columns[name].shape, name
        assert np.array_equal(rounded(name, run[name]), columns[name]), name


@pytest.mark.parametrize("preset, spec, duration", [
    ("worm-gear", "sine:freq_hz=100,amp_nm=5", 0.05),
    ("roller-gear-cam", "move:target_deg=30,loop=full_closed", 0.2),
    ("worm-gear", "step:torque_nm=3,at_s=0.01", 0.03),
])
def test_simulate_gives_the_cli_csv(cli, tmp_path, preset, spec, duration):
    out = tmp_path / "run.csv"
    cli("simulate", "--preset", preset, "--input", spec, "--duration-s", duration, "--out", out)
    run = rtid.simulate(rtid.params(preset), spec, duration_s=duration)
    assert_as_cli(run, out)
    assert ("reference_rad" in run) == spec.startswith("move:")


def test_an_array_of_torques_is_the_cli_torque_file(cli, tmp_path):
    t = np.linspace(0.0, 0.02, 401)
    q = 4.0 * np.sin(2 * np.pi * 150.0 * t) + 0.5
    torque_file = tmp_path / "torque.csv"
    np.savetxt(torque_file, np.column_stack([t, q]), fmt="%.17g", delimiter=",",
               header="time_s,motor_torque_nm", comments="")
    out = tmp_path / "run.csv"
    cli("simulate", "--preset", "worm-gear", "--input", f"file:{torque_file}", "--duration-s", 0.02,
        "--sample-s", 5e-5, "--out", out)
    p = rtid.params("worm-gear")
    run = rtid.simulate(p, q, duration_s=0.02, time_s=t, sample_s=5e-5)
    assert_as_cli(run, out)
    from_file = rtid.simulate(p, f"file:{torque_file}", duration_s=0.02, sample_s=5e-5)
    assert all(np.array_equal(run[k], from_file[k]) for k in run)


def test_integer_torques_are_accepted_as_float64():
    p = rtid.params("worm-gear")
    a = rtid.simulate(p, np.array([0, 2, 2, 0]), 0.01, time_s=[0.0, 0.001, 0.005, 0.006])
    b = rtid.simulate(p, np.array([0.0, 2.0, 2.0, 0.0]), 0.01, time_s=np.array([0.0, 0.001, 0.005, 0.006]))
    assert all(np.array_equal(a[k], b[k]) for k in a)


@pytest.mark.parametrize("kwargs, argument", [
    (dict(input=np.array([1.0, np.nan, 2.0])), r"input\[1\]"),
    (dict(input=np.array([1.0, 2.0]), time_s=np.array([0.0, 1.0, 2.0])), "input"),
    (dict(input=np.ones((2, 2))), "input: 2-dimensional"),
    (dict(input=np.array([1.0, 2.0]), time_s=np.array([0.0, 0.0])), r"time_s: \[1\]"),
    (dict(input="sine:freq_hz=100"), "missing amp_nm"),
    (dict(input="chirp:f=1"), "unknown input `chirp`"),
    (dict(input="move:target_deg=30,loop=open"), "unknown loop `open`"),
    (dict(input="none", duration_s=-1.0), "duration_s"),
    (dict(input="none", duration_s=float("nan")), "duration_s"),
    (dict(input="none", sample_s=0.0), "sample_s"),
    (dict(input="none", dt_s=-1e-5), "dt_s"),
    (dict(input="none", duration_s=1e6), "duration_s"),
    (dict(input="file:/no/such/torque.csv"), "input"),
])
def test_bad_input_raises_value_error_naming_the_argument(kwargs, argument):
    kwargs.setdefault("duration_s", 0.01)
    with pytest.raises(ValueError, match=argument):
        rtid.simulate(rtid.params("worm-gear"), **kwargs)


@pytest.mark.parametrize("values", [np.array(["a", "b"]), np.array([1 + 1j, 2]), b"1,2", np.array([True, False])])
def test_torques_of_another_type_raise_type_error(values):
    with pytest.raises(TypeError, match="input"):
        rtid.simulate(rtid.params("worm-gear"), values, 0.01)


def test_params_must_be_a_parameter_set():
    with pytest.raises(TypeError, match="params"):
        rtid.simulate({"Kw": 1.0}, "none", 0.01)
