"""The settings of the virtual tests ``rtid.run_experiment`` runs, named and
defaulted as ``rtid experiment KIND``'s flags (src/cli/experiment/), checked here."""

from __future__ import annotations


import numpy as np

from . import _names
from ._rtid import RtidError

_TORQUE_CURVE = {
    "loop": ("full_closed", "loop"),
    "amplitude_deg": (None, "positive or none"),
    "amplitude_mm": (None, "positive or none"),
    "period_s": (3.0, "positive"),
    "periods": (2.0, "positive"),
    "noise_percent": (0.0, "percent"),
    "seed": (1, "whole"),
}

_TURNING = {
    "loop": (None, "loop or none"),
    "revolutions": (1, "whole ≥ 1"),
    "run_in_deg": (10.0, "non-negative"),
    "sample_period_s": (4e-3, "positive"),
    "noise_arcsec": (0.0, "non-negative"),
    "seed": (1, "whole"),
}

#: Each kind's settings: name → (the flag's default, what it must be).
SETTINGS = {
    "frequency_response": {
        "amplitude_nm": (5.0, "positive"),
        "preload_nm": (0.0, "finite"),
        "from_hz": (10.0, "positive"),
        "to_hz": (600.0, "positive"),
        "step_hz": (10.0, "positive"),
        "refine_step_hz": (1.0, "non-negative"),
        "linear": (False, "bool"),
        "noise_percent": (0.0, "percent"),
        "complex_noise_percent": (0.0, "percent"),
        "seed": (1, "whole"),
        "response": ("table_over_motor", "response"),
        "unstated_delay_s": (0.0, "non-negative"),
    },
    "torque_curve": _TORQUE_CURVE,
    "positioning": {
        "loop": (None, "loop or none"),
        "runs": (5, "whole ≥ 2"),
        "target_step_deg": (None, "positive or none"),
        "speed_deg_per_min": (None, "positive or none"),
        "noise_arcsec": (None, "non-negative or none"),
        "target_step_mm": (None, "positive or none"),
        "travel_mm": (None, "positive or none"),
        "speed_mm_per_min": (None, "positive or none"),
        "noise_um": (None, "non-negative or none"),
        "dwell_s": (1.0, "positive"),
        "seed": (0, "whole"),
        "compensation": (None, "compensation or none"),
    },
    "friction_map": {
        "speeds_rpm": (None, "speeds or none"),
        "speeds_mm_s": (None, "speeds or none"),
        "settle_s": (0.5, "positive"),
        "average_s": (1.0, "positive"),
        "noise_percent": (0.0, "percent"),
        "scatter_percent": (0.0, "percent"),
        "seed": (1, "whole"),
    },
    "servo_trace": {
        "moves": (None, "moves or none"),
        "acceleration": (2.0, "positive"),
        "dwell_s": (0.2, "non-negative"),
    },
    "frequency_response_time": {
        "excitation": ("noise", "excitation"),
        "amplitude_nm": (5.0, "positive"),
        "preload_nm": (0.0, "finite"),
        "from_hz": (10.0, "non-negative"),
        "to_hz": (600.0, "positive"),
        "step_hz": (10.0, "positive"),
        "dwell_s": (0.5, "positive"),
        "duration_s": (16.0, "positive"),
        "period_s": (1.0, "positive"),
        "periods": (8, "whole ≥ 1"),
        "lines": ("random_odd", "lines"),
        "sample_rate_hz": (5000.0, "positive"),
        "noise_arcsec": (0.0, "non-negative"),
        "seed": (1, "whole"),
    },
    "fluctuation": dict(_TURNING, speed_deg_per_min=(180.0, "positive")),
    "unbalance": dict(_TURNING, speed_deg_per_min=(360.0, "positive"),
                      mass_kg=(None, "positive or none"), radius_m=(None, "positive or none")),
}

_CHOICES = {
    "loop": _names.OPTIONS["loop"],
    "response": _names.OPTIONS["response"],
    "excitation": ("stepped_sine", "noise", "chirp", "multisine"),
    "lines": ("full", "odd", "random_odd"),
}


def kind_of(kind) -> str:
    """``frequency-response`` or ``frequency_response`` as the latter."""
    if not isinstance(kind, str):
        raise TypeError(f"kind: expected a test's name ({', '.join(SETTINGS)}), got {type(kind).__name__}")
    k = kind.replace("-", "_")
    if k not in SETTINGS:
        raise _names.unknown("kind", "test", kind, list(SETTINGS))
    return k


def _checked(name: str, value, rule: str):
    if value is None and rule.endswith("or none"):
        return None
    rule = rule.removesuffix(" or none")
    if rule == "bool":
        if not isinstance(value, (bool, np.bool_)):
            raise TypeError(f"{name}: expected True or False, got {type(value).__name__}")
        return bool(value)
    if rule in _CHOICES:
        if not isinstance(value, str):
            raise TypeError(f"{name}: expected a string ({', '.join(_CHOICES[rule])}), got {type(value).__name__}")
        v = value.replace("-", "_")
        if v not in _CHOICES[rule]:
            raise _names.unknown(name, name, value, _CHOICES[rule])
        return v
    if rule == "speeds":
        return [_names.finite_number(v, f"{name}[{i}]") for i, v in enumerate(_sequence(value, name))]
    if rule == "moves":
        return _moves(value)
    if rule == "compensation":
        return _compensation_text(value)
    if rule.startswith("whole"):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise TypeError(f"{name}: {value!r} is not a whole number, but {type(value).__name__}")
        least = int(rule.rpartition("≥ ")[2]) if "≥" in rule else 0
        if value < least:
            raise RtidError(f"{name}: {value}: must be at least {least}")
        return int(value)
    v = _names.finite_number(value, name)
    if rule == "positive" and not v > 0:
        raise RtidError(f"{name}: {v}: must be a positive number")
    if rule == "non-negative" and v < 0:
        raise RtidError(f"{name}: {v}: must be zero or positive")
    if rule == "percent" and not 0 <= v <= 100:
        raise RtidError(f"{name}: {v}: must lie in 0..100 (%)")
    return v


def _sequence(value, name: str) -> list:
    """A list of numbers given as a list, a tuple or a 1-D array."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{name}: expected a list of numbers, got {type(value).__name__}")
    return list(value)


def _moves(value) -> list:
    """``servo_trace``'s moves: ``[(target, speed), …]`` or ``"0.1@0.2,-0.1@0.1"`` (as
    ``--moves``), rad and rad/s (m and m/s on a linear axis)."""
    if isinstance(value, str):
        pairs = []
        for part in value.split(","):
            target, at, speed = part.partition("@")
            if not at:
                raise RtidError(f"moves: `{part.strip()}`: expected TARGET@SPEED, e.g. 0.1@0.2")
            try:
                pairs.append((float(target), float(speed)))
            except ValueError:
                raise RtidError(f"moves: `{part.strip()}`: not two numbers TARGET@SPEED") from None
        value = pairs
    moves = []
    for i, move in enumerate(_sequence(value, "moves")):
        if isinstance(move, (str, bytes)) or not hasattr(move, "__len__") or len(move) != 2:
            raise TypeError(f"moves[{i}]: expected a pair (target, speed), got {move!r}")
        moves.append(tuple(_names.finite_number(v, f"moves[{i}]") for v in move))
    if not moves:
        raise RtidError("moves: no move: give at least one, or leave it out")
    return moves


def _compensation_text(value) -> str:
    """A compensation as its compensation.json text: an :class:`rtid.Compensation`,
    the file's content as a dict, or its path."""
    import json
    import os

    text = getattr(value, "text", None)
    if isinstance(text, str):
        return text
    if isinstance(value, dict):
        return json.dumps(value)
    if isinstance(value, (str, os.PathLike)):
        with open(value, encoding="utf-8-sig") as f:
            return f.read()
    raise TypeError(f"compensation: expected an rtid.Compensation, its dict or a compensation.json path, "
                    f"got {type(value).__name__}")


def settings_of(kind: str, given: dict) -> dict:
    """Every setting of `kind`: the given ones checked, the flags' defaults else."""
    spec = SETTINGS[kind]
    for name in given:
        if name not in spec:
            raise _names.unknown(name, f"setting of {kind}", name, list(spec))
    return {name: _checked(name, given[name], rule) if name in given else default
            for name, (default, rule) in spec.items()}


def read_columns(csv_path: str) -> dict:
    """The columns of an experiment CSV rtid wrote (a comment line, the names, the
    rows): float64 arrays, or arrays of words where a column holds them (a
    positioning record's direction)."""
    with open(csv_path, encoding="utf-8") as f:
        lines = [line.rstrip("\n") for line in f if line.strip() and not line.startswith("#")]
    names = [n.strip() for n in lines[0].split(",")]
    cells = list(zip(*(line.split(",") for line in lines[1:])))
    columns = {}
    for name, column in zip(names, cells):
        try:
            columns[name] = np.array([float(v) for v in column], dtype=np.float64)
        except ValueError:
            columns[name] = np.array([v.strip() for v in column])
    return columns
