"""rtid.params and rtid.modes against `rtid params --json` and `rtid modes --json`."""

import json
import math

import numpy as np
import pytest

import rtid


def test_params_are_the_cli_set_with_the_same_overrides(cli):
    p = rtid.params("worm-gear", Kw=3.5e5, theta_bw=5e-5)
    expected = cli("params", "--preset", "worm-gear", "--set", "Kw=3.5e5", "--set", "theta_bw=5e-5", "--json", json_out=True)
    assert json.loads(p.to_json()) == expected
    assert p["Kw"] == 3.5e5 and p["theta_bw"] == 5e-5
    assert p.name == "worm-gear" and p.topology == "spur_gear" and p.axis == "rotary"


def test_params_are_dict_like_with_units(cli):
    p = rtid.params("roller-gear-cam")
    described = p.describe()
    assert list(described) == list(p) and len(p) == len(described)
    assert described["Kw"]["unit"] == "N·m/rad" and described["Kw"]["value"] == p["Kw"]
    assert "Kg" not in p  # a spur-gear parameter: not of the roller-gear cam
    with pytest.raises(KeyError, match="Kg"):
        p["Kg"]
    q = p.copy()
    q["Kw"] = 2 * p["Kw"]
    assert q["Kw"] == 2 * p["Kw"] and p["Kw"] != q["Kw"]


def test_params_file_round_trip(tmp_path):
    p = rtid.params("worm-gear", Kg=1000.0)
    p.save(tmp_path / "p.json")
    assert dict(rtid.params(path=tmp_path / "p.json")) == dict(p)


@pytest.mark.parametrize("call, argument", [
    (lambda: rtid.params("worm-gear", Kx=1.0), "Kx"),
    (lambda: rtid.params("worm-gear", Kw=float("nan")), "Kw"),
    (lambda: rtid.params("worm-gear", Kw=-1.0), "Kw"),
    (lambda: rtid.params("no-such-table"), "preset"),
    (lambda: rtid.params(), "preset"),
])
def test_bad_params_raise_value_error_naming_the_argument(call, argument):
    with pytest.raises(ValueError, match=argument):
        call()


def test_setting_a_bad_value_keeps_the_old_one():
    p = rtid.params("worm-gear")
    for bad in (float("inf"), -5.0):
        with pytest.raises(ValueError, match="Kw"):
            p["Kw"] = bad
    assert p["Kw"] == rtid.params("worm-gear")["Kw"]


def test_modes_are_the_cli_modes(cli):
    m = rtid.modes(rtid.params("worm-gear", Kw=3.5e5))
    expected = cli("modes", "--preset", "worm-gear", "--set", "Kw=3.5e5", "--json", json_out=True)
    for key in ("clamped_hz", "free_hz"):
        assert m[key].dtype == np.float64 and m[key].ndim == 1
        assert m[key].tolist() == expected[key]
    for key, dofs in (("clamped_shapes", "clamped_dofs"), ("free_shapes", "free_dofs")):
        assert m[key].shape == (len(expected[key]), len(expected[dofs]))
        assert m[key].tolist() == expected[key]
        assert list(m[dofs]) == expected[dofs]
    assert all(math.isfinite(f) for f in m["clamped_hz"])
