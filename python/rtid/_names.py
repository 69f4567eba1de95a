"""The names the module's arguments take, and the closest one to a misspelt name.

The condition keys and each kind's column names are rtid's reader's (not exported by
the library): copied here, and to be kept in step with
src/io/experiment_file/conditions.rs (``Conditions::KEYS``, and ``controller``) and
src/io/experiment_file/table/kinds.rs (each kind's reserved columns) and
docs/experiment-files.md's optional columns.
"""

from __future__ import annotations

import difflib
import math
import numbers

from ._rtid import RtidError

#: A manifest's ``conditions`` keys (docs/experiment-files.md).
CONDITIONS = (
    "torque_amplitude_nm", "preload_nm", "amplitude_deg", "amplitude_m", "period_s", "loop",
    "dwell_s", "speed_deg_per_min", "ratio", "mass_kg", "radius_m", "excitation",
    "frequencies_hz", "first_line_hz", "last_line_hz", "line_step_hz", "transient_periods",
    "drive_gain", "loop_period_s", "controller", "band_hz", "response", "reference", "delay_s",
    "averages",
)

_ANGLE = ("deg", "rad", "arcsec")
_POSITION = _ANGLE + ("m", "mm", "um")
_SPEED = ("rad_s", "rpm", "deg_s", "m_s", "mm_s")
_COMMAND = ("v", "a", "nm", "n")


def _with(bases, suffixes) -> list:
    return [f"{b}_{s}" for b in bases for s in suffixes]


_MOTION = ["time_s"] + _with(["motor_angle", "table_angle"], _ANGLE)

#: The columns each kind's reader interprets (docs/experiment-files.md's table).
COLUMNS = {
    "frequency_response": ["frequency_hz", "gain_db", "gain_sigma_db", "coherence"]
    + _with(["phase", "phase_sigma"], _ANGLE),
    "torque_curve": ["time_s", "motor_torque_nm", "force_n"] + _with(["table_angle"], _ANGLE)
    + _with(["table_position"], _POSITION),
    "positioning": ["direction", "run"] + _with(["target", "deviation", "measured"], _POSITION),
    "fluctuation": _MOTION,
    "unbalance": _MOTION,
    "frequency_response_time": ["time_s", "motor_torque_nm", "motor_current_a"]
    + _with(["motor_angle", "table_angle", "load_angle"], _ANGLE),
    "servo_trace": ["time_s", "torque_nm", "force_n"]
    + _with(["reference_position", "position", "motor_position", "table_position"], _POSITION)
    + _with(["controller_output", "controller_added"], _COMMAND),
    "friction_map": ["torque_nm", "force_n", "torque_std_nm", "force_std_n", "samples", "dropped",
                     "transient"] + _with(["speed", "speed_std"], _SPEED),
}

#: How close (difflib's ratio, case ignored) an unknown column must be to a known one
#: to be taken for a misspelling of it rather than an extra column.
COLUMN_CUTOFF = 0.8


def closest(name: str, known, cutoff: float = 0.6) -> str | None:
    """The known name closest to `name` (case ignored), if any is close."""
    by_lower = {}
    for k in known:
        by_lower.setdefault(k.lower(), k)
    found = difflib.get_close_matches(name.lower(), list(by_lower), n=1, cutoff=cutoff)
    return by_lower[found[0]] if found else None


def unknown(argument: str, what: str, name: str, known) -> RtidError:
    """A ValueError: `name` is no `what` of `known`, with the closest known name."""
    hint = closest(name, known)
    tail = f"did you mean `{hint}`?" if hint else f"expected one of {', '.join(known)}"
    return RtidError(f"{argument}: unknown {what} `{name}`; {tail}")


def check_conditions(conditions) -> None:
    """Refuses a condition key rtid does not know (a misspelling), naming the closest."""
    for key in conditions:
        if not isinstance(key, str):
            raise TypeError(f"conditions: key {key!r} is not a string")
        if key not in CONDITIONS:
            raise unknown("conditions", "condition", key, CONDITIONS)


def check_columns(kind: str, columns) -> None:
    """Refuses a column that is not one `kind` reads but nearly is (a misspelling),
    naming the one it nearly is; other columns are the file's extra columns."""
    known = COLUMNS.get(kind)
    if not known:
        return
    for name in columns:
        if name in known:
            continue
        hint = closest(name, known, COLUMN_CUTOFF)
        if hint is not None:
            raise RtidError(f"{name}: not a column of a {kind} experiment; did you mean `{hint}`?"
                            " (a column a kind does not read is kept as an extra column: give"
                            " it a name of its own)")


def finite_number(value, argument: str) -> float:
    """`value` as a float: a TypeError naming `argument` if it is not a number, an
    RtidError (a ValueError) if it is not finite."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{argument}: {value!r} is not a number, but {type(value).__name__}")
    v = float(value)
    if not math.isfinite(v):
        raise RtidError(f"{argument}: {v} is not a finite number")
    return v
