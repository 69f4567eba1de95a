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
    "fluctuation": dict(_TURNING, speed_deg_per_min=(180.0, "positive")),
    "unbalance": dict(_TURNING, speed_deg_per_min=(360.0, "positive"),
                      mass_kg=(None, "positive or none"), radius_m=(None, "positive or none")),
}

_CHOICES = {"loop": ("semi_closed", "full_closed"), "response": ("table_over_motor", "motor_compliance")}


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
    if rule.startswith("whole"):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise TypeError(f"{name}: {value!r} is not a whole number, but {type(value).__name__}")
        least = 1 if rule == "whole ≥ 1" else 0
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


def settings_of(kind: str, given: dict) -> dict:
    """Every setting of `kind`: the given ones checked, the flags' defaults else."""
    spec = SETTINGS[kind]
    for name in given:
        if name not in spec:
            raise _names.unknown(name, f"setting of {kind}", name, list(spec))
    return {name: _checked(name, given[name], rule) if name in given else default
            for name, (default, rule) in spec.items()}


def read_columns(csv_path: str) -> dict:
    """The columns of an experiment CSV rtid wrote (a comment line, the names, numbers)."""
    with open(csv_path, encoding="utf-8") as f:
        lines = [line for line in f if line.strip() and not line.startswith("#")]
    names = [n.strip() for n in lines[0].split(",")]
    table = np.loadtxt(lines[1:], delimiter=",", dtype=np.float64, ndmin=2)
    return {n: np.ascontiguousarray(table[:, i]) for i, n in enumerate(names)}
