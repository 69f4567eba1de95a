"""rtid from Python: numpy in, numpy out.

rtid simulates the drive train of a CNC axis (worm-gear or roller-gear-cam rotary
tables, direct and two-mass drives, rotary or linear) and identifies its physical
parameters from measured experiments. This module wraps the Rust library's front:
each function makes the library calls the command line makes for the same job, so
it gives the command line's numbers. Units are SI throughout.

    >>> import rtid
    >>> p = rtid.params("worm-gear", Kw=3.5e5)
    >>> run = rtid.simulate(p, "sine:freq_hz=100,amp_nm=5", duration_s=0.05)
    >>> run["table_angle_rad"].shape
    (501,)

Errors are :class:`RtidError`, a :class:`ValueError` carrying rtid's message (the
file, line, column or parameter at fault); bad values (NaN, a wrong length or dtype,
an unknown or misspelt name: the closest known one is suggested) raise it naming the
argument, and an argument of the wrong type (``duration_s="1"``) raises
:class:`TypeError`.
"""

from __future__ import annotations

import contextlib
import json
import numbers
import os
import re
import tempfile
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from . import _experiments, _names, _progress, _rtid
from ._results import Curve, IdentifyResult, SweepResult
from ._rtid import VERSION, RtidError

__all__ = [
    "VERSION",
    "RtidError",
    "Params",
    "params",
    "preset_names",
    "modes",
    "simulate",
    "Channel",
    "Recording",
    "import_file",
    "Experiment",
    "experiment",
    "read_experiment",
    "run_experiment",
    "evaluate",
    "IdentifyResult",
    "Curve",
    "identify",
    "SweepResult",
    "sweep",
    "frequency_response",
    "StateSpace",
    "state_space",
    "Compensation",
    "compensate",
    "Tuning",
    "tune",
    "Prediction",
    "predict",
    "select",
]


# --- parameters -------------------------------------------------------------------


_finite_number = _names.finite_number


class Params(Mapping):
    """A parameter set: every parameter of the drive by its registry name, SI units.

    Dict-like: ``p["Kw"]``, ``p["Kw"] = 3.5e5`` (checked as ``--set`` checks it),
    ``"Kg" in p``, ``list(p)``, ``dict(p)``. :meth:`describe` gives each one's unit
    and meaning. Made by :func:`params`.
    """

    def __init__(self, inner):
        self._inner = inner

    def __getitem__(self, name: str) -> float:
        return self._inner[name]

    def __setitem__(self, name: str, value) -> None:
        _check_parameter_name(name, name)
        self._inner[name] = _finite_number(value, name)

    def __reduce__(self):
        # Pickled as its parameter file's JSON (every value to the bit, the notes).
        return (_params_from_json, (self.to_json(),))

    def __copy__(self) -> "Params":
        return self.copy()

    def __deepcopy__(self, memo) -> "Params":
        return self.copy()

    def __eq__(self, other) -> bool:
        # Two sets: the whole parameter file (name, notes, controller); else as a dict.
        if isinstance(other, Params):
            return self.to_json() == other.to_json()
        return Mapping.__eq__(self, other)

    __hash__ = None

    def __iter__(self):
        return iter(self._inner.keys())

    def __len__(self) -> int:
        return len(self._inner)

    def __contains__(self, name) -> bool:
        return isinstance(name, str) and name in self._inner

    @property
    def name(self) -> str:
        """The set's name (a preset's, or the file's)."""
        return self._inner.header()[0]

    @property
    def topology(self) -> str:
        """``spur_gear``, ``direct``, ``direct_drive`` or ``two_mass``."""
        return self._inner.header()[1]

    @property
    def axis(self) -> str:
        """``rotary`` or ``linear``."""
        return self._inner.header()[2]

    def describe(self) -> dict:
        """Each parameter: ``{"value", "unit", "meaning", "note"}`` (``rtid params``)."""
        return {
            name: {"value": value, "unit": unit, "meaning": meaning, "note": note}
            for name, value, unit, meaning, note in self._inner.describe_rows()
        }

    def to_json(self) -> str:
        """The parameter file's JSON (what ``rtid params --json`` prints)."""
        return self._inner.to_json()

    def save(self, path) -> None:
        """Writes the set as a parameter file, for ``--params`` or ``params(path=...)``."""
        self._inner.save(os.fspath(path))

    def copy(self) -> "Params":
        """An independent copy."""
        return Params(self._inner.copy())

    @property
    def loop(self) -> str:
        """The servo's loop, ``semi_closed`` or ``full_closed`` (settable: the
        parameter file's ``controller.loop``)."""
        return self._inner.loop_mode

    @loop.setter
    def loop(self, mode: str) -> None:
        if not isinstance(mode, str):
            raise TypeError(f"loop: expected semi_closed or full_closed, got {type(mode).__name__}")
        self._inner.loop_mode = mode.replace("-", "_")

    @property
    def filters(self) -> list:
        """The torque-setpoint filters, in series, as the parameter file holds them:
        ``{"type": "notch", "centre_hz", "width_hz", "depth_db"}`` (``depth_db``
        absent: a full notch) or ``{"type": "low_pass", "frequency_hz", "damping"}``
        (settable with such a list; checked against the control period)."""
        return json.loads(self._inner.filters_json())

    @filters.setter
    def filters(self, filters) -> None:
        if isinstance(filters, (str, bytes, Mapping)) or not hasattr(filters, "__iter__"):
            raise TypeError(f"filters: expected a list of filters (dicts), got {type(filters).__name__}")
        filters = list(filters)
        for i, f in enumerate(filters):
            if not isinstance(f, Mapping):
                raise TypeError(f"filters[{i}]: expected a dict such as "
                                f"{{'type': 'notch', 'centre_hz': 480.0, 'width_hz': 96.0}}, got {type(f).__name__}")
        self._inner.set_filters_json(json.dumps([dict(f) for f in filters]))

    def with_controller(self, tuned) -> "Params":
        """A copy with the controller settings (gains, filters, loop, feed-forward) of
        `tuned` — an :class:`rtid.Tuning` or its ``params``, a ``rtid tune -o`` file
        read by :func:`params` — as ``--tune`` applies them; refused for another
        topology or axis."""
        tuned = getattr(tuned, "params", tuned)
        if not isinstance(tuned, Params):
            raise TypeError(f"tuned: expected an rtid.Tuning or an rtid.Params, got {type(tuned).__name__}")
        return Params(self._inner.with_controller(tuned._inner))

    def __repr__(self) -> str:
        return f"<rtid.Params {self.name!r}: {self.topology}, {self.axis}, {len(self)} parameters>"


def _params_from_json(text: str) -> Params:
    """The set a parameter file's JSON holds (how a :class:`Params` unpickles)."""
    return Params(_rtid.params_from_json(text))


def _check_parameter_name(name, argument: str, keywords=()) -> None:
    """Refuses a name no drive has, naming the closest parameter (or keyword)."""
    if not isinstance(name, str):
        raise TypeError(f"{argument}: {name!r} is not a parameter name (a string)")
    known = _rtid.param_names()
    if name not in known:
        raise _names.unknown(argument if not keywords else name, "parameter or keyword" if keywords
                             else "parameter", name, list(keywords) + list(known))


def params(preset: str | None = None, *, path=None, **overrides) -> Params:
    """The parameter set of a preset or a parameter file, with overrides.

    Args:
        preset: a shipped preset (:func:`preset_names`: ``worm-gear``,
            ``roller-gear-cam``, …), like ``--preset``.
        path: a parameter file (JSON), like ``--params``; not with ``preset``.
        **overrides: ``NAME=VALUE`` in SI units, like ``--set NAME=VALUE``.

    Raises:
        RtidError: an unknown preset or parameter (a misspelt keyword too: ``pth=``
            names ``path``), a value outside its constraint.
        TypeError: a value that is not a number.
    """
    if preset is not None and not isinstance(preset, str):
        raise TypeError(f"preset: expected a preset's name, got {type(preset).__name__}")
    for name in overrides:
        _check_parameter_name(name, name, keywords=("preset", "path"))
    pairs = [(name, _finite_number(v, name)) for name, v in overrides.items()]
    return Params(
        _rtid.load_params(preset, None if path is None else os.fspath(path), pairs)
    )


def preset_names() -> list:
    """The names of the shipped presets."""
    return list(_rtid.preset_names())


def _params_arg(p) -> object:
    if not isinstance(p, Params):
        raise TypeError(f"params: expected an rtid.Params (rtid.params(...)), got {type(p).__name__}")
    return p._inner


def modes(params: Params) -> dict:
    """Natural frequencies and mode shapes of the linearised drive (``rtid modes``).

    Returns a dict: ``clamped_hz`` and ``free_hz`` (float64 arrays, Hz, ascending:
    motor held, and motor free without the rigid-body mode), ``clamped_shapes`` and
    ``free_shapes`` (arrays modes × coordinates, largest component +1),
    ``clamped_dofs`` and ``free_dofs`` (the coordinates' names).
    """
    return dict(_rtid.modes(_params_arg(params)))


# --- simulation -------------------------------------------------------------------


def _real_array(values, argument: str, allow_nan: bool = False) -> np.ndarray:
    """A 1-D contiguous float64 copy of `values`, or a ValueError naming `argument`."""
    if isinstance(values, (str, bytes, Mapping)):
        raise TypeError(f"{argument}: expected numbers (an array), got {type(values).__name__}")
    a = np.asarray(values)
    if a.dtype == object or a.dtype.kind not in "iufb":
        raise TypeError(f"{argument}: dtype {a.dtype} is not a real number type (give float64)")
    if a.dtype.kind == "b":
        raise TypeError(f"{argument}: booleans are not numbers (give float64)")
    if a.ndim != 1:
        raise RtidError(f"{argument}: {a.ndim}-dimensional, shape {a.shape}: give a 1-D array")
    if a.size == 0:
        raise RtidError(f"{argument}: empty array")
    a = np.ascontiguousarray(a, dtype=np.float64)
    if not allow_nan:
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise RtidError(f"{argument}[{bad[0]}] = {a[bad[0]]}: not a finite number")
    return a


def simulate(
    params: Params,
    input,
    duration_s: float,
    *,
    time_s=None,
    dt_s: float | None = None,
    sample_s: float = 1e-4,
    load_nm: float = 0.0,
) -> dict:
    """A time simulation of the nonlinear model from rest (``rtid simulate``).

    Args:
        params: the drive (:func:`params`).
        input: the command line's input specification — ``"sine:freq_hz=100,amp_nm=5"``,
            ``"step:torque_nm=2,at_s=0.01"``, ``"file:torque.csv"``,
            ``"move:target_deg=30,loop=full_closed"``, ``"none"`` — or an array of motor
            torques, N·m, at the times ``time_s`` (default every ``sample_s``),
            linearly interpolated and held beyond the ends, as ``file:`` does.
        duration_s: simulated time, s.
        time_s: the times of an array ``input``, s, strictly increasing.
        dt_s: integration step, s (default: from the stiffest mode).
        sample_s: period of the output samples, s (rounded to whole steps).
        load_nm: constant external torque on the table, N·m.

    Returns:
        A dict of float64 arrays named as the CLI's CSV columns: ``time_s``,
        ``motor_torque_nm``, the states (``motor_angle_rad``, …,
        ``table_angle_rad``, ``table_velocity_rad_per_s``, …) and for a ``move:``
        ``reference_rad``. The kernel runs with the GIL released.
    """
    duration_s = _finite_number(duration_s, "duration_s")
    sample_s = _finite_number(sample_s, "sample_s")
    load_nm = _finite_number(load_nm, "load_nm")
    if dt_s is not None:
        dt_s = _finite_number(dt_s, "dt_s")
    p = _params_arg(params)
    if isinstance(input, (str, os.PathLike)):
        spec, torque, t = os.fspath(input), None, None
    else:
        spec, torque = None, _real_array(input, "input")
        if time_s is None:
            t = np.arange(torque.size, dtype=np.float64) * sample_s
        else:
            t = _real_array(time_s, "time_s")
            if t.size != torque.size:
                raise RtidError(f"input: {torque.size} torques for {t.size} times in time_s: give one torque per time")
    with _partial_on_interrupt(dict):
        return dict(_rtid.simulate(p, duration_s, spec, torque, t, dt_s, sample_s, load_nm))


@contextlib.contextmanager
def _partial_on_interrupt(convert):
    """A KeyboardInterrupt out of a long call carries what the call finished (the
    extension's ``partial``) as ``result``, converted by `convert`."""
    try:
        yield
    except KeyboardInterrupt as e:
        partial = getattr(e, "partial", None)
        if partial is not None:
            e.result = convert(partial)
            del e.partial
        raise


# --- files labs export --------------------------------------------------------------


@dataclass(repr=False)
class Channel:
    """One channel of a recording: samples (float64, or complex128 for a complex
    channel), the unit as the file spells it, and the abscissa when the file gives
    one (an array of times or frequencies in ``abscissa_unit``)."""

    name: str
    unit: str
    samples: np.ndarray
    abscissa: np.ndarray | None = None
    abscissa_unit: str = ""

    def __repr__(self) -> str:
        unit = f", {self.unit}" if self.unit else ""
        return f"<rtid.Channel {self.name!r}{unit}: {self.samples.size} samples of {self.samples.dtype}>"


@dataclass(repr=False)
class Recording:
    """What a reader found in one file: its format, channels by name, notes."""

    format: str
    channels: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def __repr__(self) -> str:
        names = ", ".join(self.channels)
        return f"<rtid.Recording {self.format}: {len(self.channels)} channels ({names})>"


def _channel(c: dict) -> Channel:
    samples = c["samples"] if "samples" in c else c["re"] + 1j * c["im"]
    a = c["abscissa"]
    if "values" in a:
        abscissa = a["values"]
    elif "step" in a:
        abscissa = a["start"] + a["step"] * np.arange(samples.size, dtype=np.float64)
    else:
        abscissa = None
    return Channel(c["name"], c["unit"], samples, abscissa, a.get("unit", ""))


def import_file(path) -> Recording:
    """The channels of a file a lab exported (``rtid import FILE --list``): MATLAB
    MAT-files (v5/v7), TwinCAT Scope View CSV, EPOS Studio CSV, UFF 58/58b, delimited
    text. Each channel's samples as a numpy array with its unit."""
    r = _rtid.import_file(os.fspath(path))
    channels = {}
    for c in r["channels"]:
        channels[c["name"]] = _channel(c)
    return Recording(r["format"], channels, list(r["notes"]))


# --- experiments ----------------------------------------------------------------


class Experiment:
    """An experiment: a manifest (kind, conditions, …) and its data columns.

    Made by :func:`experiment` from arrays or by :func:`read_experiment` from a
    manifest file; checked by rtid's reader either way (missing or bad columns raise
    RtidError naming them).
    """

    def __init__(self, manifest: dict, columns: dict | None, path: str | None, name: str):
        self.manifest = manifest
        self.columns = columns
        self.path = path
        self.name = name

    @property
    def kind(self) -> str:
        """The experiment's kind (``servo_trace``, ``frequency_response``, …)."""
        return self.manifest["kind"]

    def _written(self, folder: str) -> str:
        """The manifest path: the file itself, or the arrays written into `folder`
        (full float64 precision: rtid reads back the same numbers)."""
        if self.path is not None:
            return self.path
        base = os.path.join(folder, f"experiment-{id(self)}")
        _WRITTEN[base] = self.name
        names = list(self.columns)
        # Numbers at full precision; text columns (a positioning record's direction)
        # as they are.
        cells = [[f"{v:.17g}" for v in c.tolist()] if c.dtype.kind in "iuf" else [str(v) for v in c]
                 for c in (self.columns[n] for n in names)]
        with open(base + ".csv", "w", encoding="utf-8") as f:
            f.write(",".join(names) + "\n")
            f.writelines(",".join(row) + "\n" for row in zip(*cells))
        manifest = dict(self.manifest, data=os.path.basename(base) + ".csv")
        with open(base + ".json", "w", encoding="utf-8") as f:
            json.dump(manifest, f)
        return base + ".json"

    def __repr__(self) -> str:
        return f"<rtid.Experiment {self.kind} {self.name!r}>"


#: The names of the experiments written to temporary files, by file stem: an error
#: of rtid's reader names the experiment, never the temporary file.
_WRITTEN: dict = {}


@contextlib.contextmanager
def _temporary_folder():
    """A temporary folder for experiments' files; rtid's errors that name a file in
    it name the experiment (and the row of its columns, or its manifest) instead."""
    with tempfile.TemporaryDirectory(prefix="rtid-") as folder:
        try:
            yield folder
        except RtidError as e:
            text = str(e)
            if folder not in text:
                raise
            raise RtidError(_without_folder(text, folder)) from None
        finally:
            for base in [b for b in list(_WRITTEN) if b.startswith(folder)]:
                _WRITTEN.pop(base, None)


def _without_folder(text: str, folder: str) -> str:
    """`text` with each path into `folder` replaced by what it holds."""
    pattern = re.escape(folder) + r"[/\\]+(experiment-\d+)\.(json|csv)(?:, line (\d+))?(?:, column (\d+))?"

    def named(m):
        name = _WRITTEN.get(os.path.join(folder, m.group(1)), "the experiment")
        if m.group(2) == "json":
            return f"the manifest of experiment {name!r} (kind, conditions, mechanism, notes)"
        if m.group(3):
            # The CSV's first line names the columns: line k holds row k − 2.
            return f"experiment {name!r}, row {int(m.group(3)) - 2} of the columns"
        return f"the columns of experiment {name!r}"

    text, rows = re.subn(pattern, named, text)
    if rows:
        # The reader's "(previous row X)" gives the previous row's value, not its number.
        text = re.sub(r"\(previous row ([^)]+)\)", r"(the previous row's value: \1)", text)
    return text.replace(folder, "a temporary folder")


#: Columns of words, not numbers: a positioning record's approach direction (``up``,
#: ``down``; ``ccw``, ``cw``).
_TEXT_COLUMNS = ("direction",)


def _text_array(values, argument: str) -> np.ndarray:
    """A 1-D array of words (rtid's reader checks them)."""
    a = np.asarray(values)
    if a.ndim != 1 or a.size == 0:
        raise RtidError(f"{argument}: give a 1-D array of words (up, down), shape {a.shape}")
    if a.dtype.kind not in "US":
        raise TypeError(f"{argument}: expected words (up, down), got dtype {a.dtype}")
    return a.astype(str)


def experiment(kind: str, *, conditions: dict | None = None, mechanism: str | None = None,
               notes: str | None = None, name: str | None = None, **columns) -> Experiment:
    """An experiment from arrays, no files needed.

    Args:
        kind: ``servo_trace``, ``frequency_response``, ``torque_curve``,
            ``positioning``, ``friction_map``, … (docs/experiment-files.md).
        conditions: the manifest's ``conditions`` (e.g. ``drive_gain``,
            ``loop_period_s`` of a servo trace).
        mechanism, notes: the manifest's free text.
        name: how results name it (default ``kind``).
        **columns: the data columns by their file names, with units in the names:
            ``time_s=…``, ``motor_position_m=…``, ``reference_position_m=…``,
            ``force_n=…``, ``frequency_hz=…``, ``gain_db=…``; 1-D arrays of one
            length.

    Raises:
        RtidError: a column that is not a 1-D real array, holds NaN or has another
            length (named), or what rtid's reader refuses (a missing column, …).
    """
    if not isinstance(kind, str):
        raise TypeError(f"kind: expected a name such as 'servo_trace', got {kind!r}")
    if kind not in _names.COLUMNS:
        raise _names.unknown("kind", "kind", kind, list(_names.COLUMNS))
    if conditions is not None:
        if not isinstance(conditions, Mapping):
            raise TypeError(f"conditions: expected a dict, got {type(conditions).__name__}")
        _names.check_conditions(conditions)
        conditions = dict(conditions)
    for argument, value in (("mechanism", mechanism), ("notes", notes), ("name", name)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{argument}: expected a string, got {type(value).__name__}")
    if not columns:
        raise RtidError("columns: no data column given (e.g. time_s=..., force_n=...)")
    _names.check_columns(kind, columns)
    arrays = {n: _text_array(v, n) if n in _TEXT_COLUMNS else _real_array(v, n) for n, v in columns.items()}
    lengths = {n: a.size for n, a in arrays.items()}
    first = next(iter(arrays))
    for n, size in lengths.items():
        if size != lengths[first]:
            raise RtidError(f"{n}: {size} values, but {first} has {lengths[first]}: give columns of one length")
    manifest = {"kind": kind}
    for key, value in (("mechanism", mechanism), ("notes", notes), ("conditions", conditions)):
        if value is not None:
            manifest[key] = value
    exp = Experiment(manifest, arrays, None, name or kind)
    with _temporary_folder() as d:
        _rtid.read_experiment(exp._written(d))
    return exp


def read_experiment(path) -> Experiment:
    """An experiment file (a JSON manifest with its CSV), read and checked by rtid."""
    path = os.fspath(path)
    _rtid.read_experiment(path)
    with open(path, encoding="utf-8-sig") as f:
        manifest = json.load(f)
    return Experiment(manifest, None, path, path)


def run_experiment(kind: str, params: Params, **settings) -> Experiment:
    """A test run on the model: the experiment ``rtid experiment KIND`` writes (the
    same manifest and columns, every number to the bit).

    Args:
        kind: ``frequency_response``, ``torque_curve``, ``fluctuation``,
            ``unbalance``, ``positioning``, ``friction_map``, ``servo_trace`` or
            ``frequency_response_time`` (``frequency-response`` … as on the command
            line).
        params: the drive (:func:`params`; an identified one: ``fit.params``; with a
            tuned controller, ``--tune``: ``p.with_controller(tuning)``).
        **settings: the test's flags, ``-`` as ``_``, with the flags' defaults:

            - frequency_response: ``amplitude_nm`` (5), ``preload_nm`` (0),
              ``from_hz`` (10), ``to_hz`` (600), ``step_hz`` (10),
              ``refine_step_hz`` (1; 0: no refinement), ``linear`` (False: a
              nonlinear simulation per frequency, seconds; True: the linear model,
              milliseconds), ``noise_percent``, ``complex_noise_percent`` (0),
              ``seed`` (1), ``response`` (``table_over_motor``, or with
              ``linear=True`` ``motor_compliance``), ``unstated_delay_s`` (0);
            - torque_curve: ``loop`` (``full_closed``), ``amplitude_deg`` (30) or on
              a linear axis ``amplitude_mm`` (50), ``period_s`` (3), ``periods`` (2),
              ``noise_percent`` (0), ``seed`` (1);
            - fluctuation and unbalance: ``loop`` (the set's), ``revolutions`` (1),
              ``run_in_deg`` (10), ``sample_period_s`` (0.004), ``noise_arcsec`` (0),
              ``seed`` (1), ``speed_deg_per_min`` (180; unbalance 360); unbalance
              also ``mass_kg``, ``radius_m`` (the set's unbalance, else 10 kg at
              0.1 m);
            - positioning (ISO 230-2): ``loop`` (the set's), ``runs`` (5),
              ``dwell_s`` (1), ``seed`` (0), on a rotary axis ``target_step_deg``
              (30), ``speed_deg_per_min`` (3600), ``noise_arcsec`` (0), on a linear
              one ``target_step_mm`` (50), ``travel_mm`` (500), ``speed_mm_per_min``
              (3000), ``noise_um`` (0); ``compensation`` (a :class:`Compensation`,
              its dict or a compensation.json path) run in the controller;
            - friction_map: ``speeds_rpm`` (or on a linear axis ``speeds_mm_s``; a
              list, each positive speed run both ways; default ±0.2 … ±50 % of the
              speed limit), ``settle_s`` (0.5), ``average_s`` (1), ``noise_percent``,
              ``scatter_percent`` (0), ``seed`` (1);
            - servo_trace: ``moves`` (``[(target, speed), …]`` or ``"0.1@0.2,…"``,
              rad and rad/s or m and m/s; default ``0.1@0.2, -0.1@0.1, 0@0.05``),
              ``acceleration`` (2), ``dwell_s`` (0.2);
            - frequency_response_time: ``excitation`` (``noise``, ``stepped_sine``,
              ``chirp``, ``multisine``), ``amplitude_nm`` (5), ``preload_nm`` (0),
              ``from_hz`` (10), ``to_hz`` (600), ``step_hz`` (10), ``dwell_s`` (0.5),
              ``duration_s`` (16), ``period_s`` (1), ``periods`` (8), ``lines``
              (``random_odd``, ``odd``, ``full``), ``sample_rate_hz`` (5000),
              ``noise_arcsec`` (0), ``seed`` (1).

    Returns:
        An :class:`Experiment` holding the manifest and the columns as arrays, for
        :func:`evaluate` and :func:`identify`. The test runs with the GIL released;
        Ctrl-C stops it (KeyboardInterrupt), and a request beyond the command line's
        work limits (an hour simulated, 10⁵ points) is refused before it starts.

    Raises:
        RtidError: an unknown test or setting (with the closest known name), a bad
            value (named); TypeError: a setting of the wrong type.
    """
    k = _experiments.kind_of(kind)
    values = _experiments.settings_of(k, settings)
    p = _params_arg(params)
    with tempfile.TemporaryDirectory(prefix="rtid-") as d:
        path = _rtid.run_experiment(k, p, values, d)
        with open(path, encoding="utf-8") as f:
            manifest = json.load(f)
        columns = _experiments.read_columns(os.path.join(d, manifest.pop("data")))
    return Experiment(manifest, columns, None, f"{k} of {params.name}")


def _as_experiment(e, argument: str) -> Experiment:
    if isinstance(e, Experiment):
        return e
    if isinstance(e, (str, os.PathLike)):
        return read_experiment(e)
    raise TypeError(f"{argument}: expected an rtid.Experiment or a manifest path, got {type(e).__name__}")


def evaluate(experiment, params: Params | None = None, *, runs: str | None = None, compensation=None,
             segment_s: float | None = None, min_coherence: float | None = None,
             settle_fraction: float | None = None, cutoff_hz: float | None = None,
             decimation: int | None = None, trim_s: float | None = None,
             min_speed: float | None = None) -> dict:
    """The statistics ``rtid evaluate --json`` gives of an experiment, as a dict.

    By kind: the resonances (and with the phase the modes) of a frequency response; a
    torque curve's friction and reversals; a positioning record's ISO 230-2 values
    (``runs="4-5"``: those runs; ``compensation=``: a :class:`Compensation`, its dict
    or a compensation.json path — the values as the compensated axis would show them,
    beside the uncompensated); the friction laws of a friction map; a servo trace's
    friction law by IDIM-LS (``cutoff_hz``, ``decimation``, ``trim_s``, ``min_speed``
    as the flags; with ``params``, at the motor of a geared model, and the trace
    replayed on the model: ``simulation_error``); a fluctuation or unbalance test's
    deviations in arc-seconds; a raw time record's gain curve (stepped-sine
    demodulation, or H1 with coherence: ``segment_s``, ``min_coherence``,
    ``settle_fraction``) or a periodic multisine's two channels, noise, modes and
    distortion (docs/multisine.md)."""
    exp = _as_experiment(experiment, "experiment")
    p = None if params is None else _params_arg(params)
    options = {
        "runs": None if runs is None else (runs if isinstance(runs, str) else str(_whole(runs, "runs"))),
        "compensation": None if compensation is None else _experiments._compensation_text(compensation),
        "segment_s": None if segment_s is None else _finite_number(segment_s, "segment_s"),
        "min_coherence": None if min_coherence is None else _finite_number(min_coherence, "min_coherence"),
        "settle_fraction": None if settle_fraction is None else _finite_number(settle_fraction, "settle_fraction"),
        "cutoff_hz": None if cutoff_hz is None else _finite_number(cutoff_hz, "cutoff_hz"),
        "decimation": None if decimation is None else _whole(decimation, "decimation", 0),
        "trim_s": None if trim_s is None else _finite_number(trim_s, "trim_s"),
        "min_speed": None if min_speed is None else _finite_number(min_speed, "min_speed"),
    }
    with _temporary_folder() as d:
        return json.loads(_rtid.evaluate(exp._written(d), exp.name, p, options))


# --- identification ---------------------------------------------------------------


def _profile_names(profile):
    """``identify``'s ``profile`` as the module takes it: None, [] (all) or names."""
    if profile is None or profile is False:
        return None
    if profile is True:
        return []
    if isinstance(profile, str):
        return [n.strip() for n in profile.split(",")]
    names = list(profile)
    if not all(isinstance(n, str) and n.strip() for n in names):
        raise RtidError(f"profile: {profile!r}: give parameter names, or True for all")
    return names


def _whole(n, name: str, least: int = 1) -> int:
    """A whole number argument of at least `least`: a TypeError naming it if it is
    not a whole number, a ValueError if it is too small."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise TypeError(f"{name}: {n!r} is not a whole number, but {type(n).__name__}")
    if n < least:
        raise RtidError(f"{name}: {n!r}: must be at least {least}")
    return int(n)


def _flag(value, name: str) -> bool:
    """A True/False argument: a TypeError naming it otherwise."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(value).__name__}")
    return bool(value)


def _choice(value, name: str, choices, what: str | None = None) -> str:
    """A string argument among `choices` (each a `what`, default the argument's
    name), named in the error with the closest."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected a string ({', '.join(choices)}), got {type(value).__name__}")
    if value not in choices:
        raise _names.unknown(name, what or name, value, choices)
    return value


def _names_list(value, name: str, allow_empty: bool = False) -> list:
    """A list of names (a comma-separated string or an iterable of strings)."""
    if isinstance(value, str):
        value = [n.strip() for n in value.split(",")]
    elif isinstance(value, (Mapping, numbers.Number)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{name}: expected a list of names, got {type(value).__name__}")
    names = list(value)
    for n in names:
        if not isinstance(n, str):
            raise TypeError(f"{name}: {n!r} is not a name (a string)")
    if not names and not allow_empty:
        raise RtidError(f"{name}: an empty list: name at least one, or leave {name} out (None)")
    return names


def _bound(name: str, bound) -> tuple:
    """``bounds[name]`` as (low, high): a TypeError if it is not a pair of numbers."""
    if isinstance(bound, (str, bytes, Mapping)) or not hasattr(bound, "__len__") or len(bound) != 2:
        raise TypeError(f"bounds[{name}]: expected a pair (low, high) of numbers, got {bound!r}")
    lo, hi = bound
    return _finite_number(lo, f"bounds[{name}]"), _finite_number(hi, f"bounds[{name}]")


def _uncertain(uncertain) -> list:
    """``identify``'s held ranges as (name, relative half-range) pairs."""
    if uncertain is None:
        return []
    if not isinstance(uncertain, Mapping):
        raise TypeError(f"uncertain: expected a dict {{name: relative half-range}}, "
                        f"got {type(uncertain).__name__}")
    out = []
    for name, half in uncertain.items():
        _check_parameter_name(name, "uncertain")
        out.append((name, _finite_number(half, f"uncertain[{name}]")))
    return out


def identify(experiments, params: Params, fit=None, *, bounds: dict | None = None,
             method: str | None = None, model: str = "auto", starts: int | None = None,
             seed: int = 1, max_iters: int = 50, start: str = "estimate",
             weights=None, objectives=None, profile=None,
             resample: int | None = None, uncertain: dict | None = None,
             intervals: str = "auto", joint: bool = False,
             checkpoint=None, resume: bool = False, progress=None) -> IdentifyResult:
    """Identifies parameters from experiments (``rtid identify``).

    Args:
        experiments: an :class:`Experiment` or manifest path, or a list of them.
        params: the parameter set the others stay at (:func:`params`).
        fit: names of the parameters to fit, a list or ``"Kw,Kg"`` (default, None:
            what the experiments determine; an empty list is refused).
        bounds: ``{"Kw": (1e5, 1e7)}``, SI (``--bound``).
        method: ``lsq``, ``lm``, ``nelder-mead`` or ``pso`` (``--method``).
        model: ``auto``, ``linear`` or ``nonlinear`` (``--model``).
        starts: the number of starts of the local search (a Latin hypercube about
            the start values; default 4, 1 when a torque curve or an unbalance test
            is fitted: each of its evaluations is seconds of simulation).
        seed: the seed of the Latin hypercube and of the particle swarm.
        max_iters: the iteration limit of each local search.
        start: ``"estimate"`` — at an experiment's direct estimate where it offers
            one (a servo trace's IDIM-LS for Jt, Ct, ft, Tload), else at ``params``'
            values; ``"given"`` — at ``params``' values always.
        weights: each experiment's weight in the joint cost, in order (default 1
            each; relative, within 1e-6..1e6).
        objectives: the objectives to use (default: by each experiment's kind);
            each experiment feeds those of them it can read: ``resonance`` (relative
            error of the resonance frequencies), ``peak_amplitude`` (dB error of the
            peaks' heights), ``gain_curve`` (dB error of the gain at every measured
            frequency, and of the phase where the file has one), ``gain_near_peaks``
            (the same within ±3 % of each resonance), ``torque_curve`` (the motor
            torque of the closed-loop torque test, sample by sample),
            ``unbalance_step`` (the table angles where an unbalance test's deviation
            steps across the backlash), ``servo_trace`` (the trace replayed through
            the servo: force and position), ``friction_map`` (the steady motor torque
            at each run's speed).
        profile: names to profile (``True``: every fitted parameter), for intervals
            that hold where the cost is not a bowl (``--profile``).
        resample: bootstrap replicates of the residuals' blocks (``--resample``;
            default: 12 where the intervals are the bootstrap's).
        uncertain: held parameters' relative half-ranges in place of or beside the
            parameter set's own (``params.ranges``, a preset's held ranges, carried by
            default), e.g. ``{"Kw": 0.1, "theta_bg": 0}`` (``--uncertain Kw=10%``; 0
            holds it exactly): on a smooth cost the fit is repeated at each end of
            each range and the result's ``held`` says how the fitted parameters
            follow; in a bootstrap each replicate draws them instead.
        intervals: ``"auto"`` (default: the bootstrap where the cost is rough — a
            torque curve, an unbalance test, a servo trace — or the corrections did
            not converge, else the standard errors), ``"standard-errors"`` or
            ``"bootstrap"`` (``--intervals``).
        joint: fit every parameter on the joint cost of every experiment at once
            (``--joint``); by default several experiments are fitted by plan — each
            parameter first from the record that carries the most information about
            it, the others held, then the shared ones refined jointly.
        checkpoint: a file the search's state is written to as it goes
            (``--checkpoint``); with ``resume=True`` the search continues from it to
            the result it would have reached (``--resume``).
        progress: a progress bar of the searches' iterations: None (default) shows
            a tqdm bar where tqdm is installed and the output is watched (a notebook,
            a terminal), True always (tqdm required), False never; or a function
            called as ``progress(done, budget, evaluations)``.

    Returns:
        An :class:`IdentifyResult`: ``values``, ``standard_errors``, ``covariance``,
        ``intervals``, ``report()``, ``to_pandas()``, ``curves`` (each experiment's
        data beside the model), ``params``.

    Raises:
        RtidError: a bad value (an unknown parameter or option, with the closest
            known name), or what rtid refuses of the experiments.
        TypeError: an argument of the wrong type.

    Ctrl-C (KeyboardInterrupt, a notebook's interrupt) ends the search: the best point
    so far is returned, ``interrupted`` set and a warning issued. The search runs with
    the GIL released.
    """
    if isinstance(experiments, (Experiment, str, os.PathLike)):
        experiments = [experiments]
    elif not isinstance(experiments, (list, tuple)):
        raise TypeError(f"experiments: expected an rtid.Experiment, a manifest path or a list of them, "
                        f"got {type(experiments).__name__}")
    fit = [] if fit is None else _names_list(fit, "fit")
    for name in fit:
        _check_parameter_name(name.strip(), "fit")
    if bounds is not None and not isinstance(bounds, Mapping):
        raise TypeError(f"bounds: expected a dict {{name: (low, high)}}, got {type(bounds).__name__}")
    for name in bounds or {}:
        _check_parameter_name(name, "bounds")
    if method is not None:
        _choice(method.replace("_", "-") if isinstance(method, str) else method, "method",
                _names.OPTIONS["method"])
    options = {
        "fit": fit,
        "bounds": [(n, *_bound(n, b)) for n, b in (bounds or {}).items()],
        "method": method,
        "fidelity": _choice(model, "model", ("auto", "linear", "nonlinear")),
        "starts": None if starts is None else _whole(starts, "starts"),
        "seed": _whole(seed, "seed", 0),
        "max_iters": _whole(max_iters, "max_iters"),
        "start": _choice(start, "start", ("estimate", "given")),
        "weights": None if weights is None else [_finite_number(w, "weights") for w in weights],
        "objectives": None if objectives is None else [
            _choice(o.replace("-", "_"), "objectives", _names.OPTIONS["objectives"], what="objective")
            for o in _names_list(objectives, "objectives")],
        "profile": _profile_names(profile),
        "resample": None if resample is None else _whole(resample, "resample"),
        "uncertain": _uncertain(uncertain),
        "intervals": _choice(intervals, "intervals", ("auto", "standard-errors", "bootstrap")),
        "joint": _flag(joint, "joint"),
        "checkpoint": None if checkpoint is None else os.fspath(checkpoint),
        "resume": _flag(resume, "resume"),
    }
    exps = [_as_experiment(e, f"experiments[{i}]") for i, e in enumerate(experiments)]
    if options["checkpoint"] is not None:
        inputs = [os.path.realpath(e.path) for e in exps if e.path is not None]
        if os.path.realpath(options["checkpoint"]) in inputs:
            raise RtidError(f"checkpoint: {options['checkpoint']} is an input of the fit: give a file of its own")
    callback, close = _progress.reporter(progress, "identify", "it")
    try:
        with _temporary_folder() as d:
            paths = [(e._written(d), e.name) for e in exps]
            text, identified, comparisons, stopped, statistics = _rtid.identify(
                paths, _params_arg(params), options, callback)
    finally:
        close()
    result = IdentifyResult(json.loads(text), Params(identified), comparisons, stopped, statistics)
    if result.interrupted:
        warnings.warn("rtid.identify: interrupted; the result is the best point so far", RuntimeWarning, stacklevel=2)
    return result


# --- sweeps -----------------------------------------------------------------------


def sweep(params: Params, vary, outputs, *, method: str = "grid", samples: int = 256,
          bootstrap: int = 500, trajectories: int = 20, levels: int = 4, step: float = 0.01,
          seed: int = 0, tests: str = "short", out=None, resume: bool = False,
          progress=None) -> SweepResult:
    """A sensitivity sweep (``rtid sweep``).

    Args:
        params: the base parameter set.
        vary: ``NAME=LOW..HIGH[:log][:LEVELS]`` specifications, e.g.
            ``["Kw=1e5..1e6:log:20"]`` (a single string is one).
        outputs: what to compute at each point, e.g. ``["resonances"]``.
        method: ``grid``, ``local``, ``morris`` or ``sobol``, with ``samples``,
            ``bootstrap``, ``trajectories``, ``levels``, ``step``, ``seed``,
            ``tests`` as the flags of the same names.
        out: the sweep CSV to keep (default: a temporary file, removed); each row is
            written to it as it is computed.
        resume: continue the sweep file ``out`` an earlier call left unfinished
            (interrupted): only its missing rows are computed (``--resume``).
        progress: a progress bar of the design's points, as :func:`identify`'s (a
            function is called as ``progress(done, total)``).

    Returns:
        A :class:`SweepResult`: ``design``, ``outputs``, ``indices``, and as pandas
        tables ``to_pandas()`` and ``indices_to_pandas()``.

    Ctrl-C stops the sweep within a fraction of a second and raises
    KeyboardInterrupt; its ``result`` attribute is a :class:`SweepResult` of the rows
    finished (no indices), which ``out`` also holds for ``resume=True``.
    """
    vary = [vary] if isinstance(vary, str) else _names_list(vary, "vary", allow_empty=True)
    for spec in vary:
        name = re.split(r"[=:]", spec, maxsplit=1)[0].strip()
        if name:
            _check_parameter_name(name, "vary")
    outputs = [outputs] if isinstance(outputs, str) else _names_list(outputs, "outputs", allow_empty=True)
    outputs = [_choice(o.strip(), "outputs", _names.OPTIONS["outputs"], what="output") for o in outputs]
    options = dict(vary=vary, outputs=outputs,
                   method=_choice(method, "method", ("grid", "local", "morris", "sobol")),
                   samples=_whole(samples, "samples"), bootstrap=_whole(bootstrap, "bootstrap", 0),
                   trajectories=_whole(trajectories, "trajectories"), levels=_whole(levels, "levels"),
                   step=_finite_number(step, "step"), seed=_whole(seed, "seed", 0),
                   tests=_choice(tests, "tests", ("short", "full")))
    if not isinstance(resume, (bool, np.bool_)):
        raise TypeError(f"resume: expected True or False, got {type(resume).__name__}")
    if resume and out is None:
        raise RtidError("resume: give out=, the sweep file to resume")
    callback, close = _progress.reporter(progress, "sweep", "point")
    try:
        with tempfile.TemporaryDirectory(prefix="rtid-") as d, _partial_on_interrupt(_sweep_result):
            path = os.fspath(out) if out is not None else os.path.join(d, "sweep.csv")
            r = _rtid.sweep(_params_arg(params), options, path, callback, bool(resume))
    finally:
        close()
    return _sweep_result(r)


def _sweep_result(r: dict) -> SweepResult:
    return SweepResult(list(r["factors"]), r["design"], list(r["output_columns"]), r["outputs"],
                       r["index"], json.loads(r["indices_json"]))


# --- the linear model -------------------------------------------------------------


@dataclass(repr=False)
class StateSpace:
    """A state-space model ẋ = A·x + B·u, y = C·x + D·u with its names: unpacks as
    ``A, B, C, D = rtid.state_space(p)``.

    Attributes:
        A, B, C, D: the matrices (float64 arrays).
        states, inputs, outputs: the names of x, u and y, in the matrices' order.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: list
    inputs: list
    outputs: list

    def __iter__(self):
        return iter((self.A, self.B, self.C, self.D))

    def __repr__(self) -> str:
        return (f"<rtid.StateSpace {len(self.states)} states ({', '.join(self.states)}), "
                f"inputs {', '.join(self.inputs)}>")


def state_space(params: Params) -> StateSpace:
    """The linearised drive as a state-space model (docs/model.md §2, §11: no
    backlash, no Coulomb friction, no fluctuation, no controller).

    ẋ = A·x + B·u, y = C·x + D·u, the state x = [q, q̇]: the coordinates q
    (``theta_m``, ``theta_w``, ``x_w``, ``theta_t``: rad, ``x_w`` in m; those of the
    drive's topology, as :func:`modes`' ``free_dofs``) and their rates
    (``theta_m_dot``, …); the inputs u: ``motor_torque`` (N·m on the motor) and
    ``table_torque`` (N·m on the table; N on a linear axis's carriage); the outputs
    y: the states (C = I, D = 0).

    Returns:
        A :class:`StateSpace`: ``A, B, C, D = rtid.state_space(p)`` (float64
        arrays; e.g. ``control.ss(A, B, C, D)``), with ``states``, ``inputs`` and
        ``outputs`` naming their rows and columns.
    """
    m = _rtid.state_space(_params_arg(params))
    return StateSpace(m["A"], m["B"], m["C"], m["D"], list(m["states"]), list(m["inputs"]),
                      list(m["outputs"]))


def frequency_response(params: Params, freqs_hz, *, input: str = "motor_torque",
                       output: str = "table_over_motor") -> np.ndarray:
    """The linearised drive's complex frequency response at `freqs_hz` (Hz).

    Args:
        params: the drive (:func:`params`).
        freqs_hz: frequencies, Hz (a number or a 1-D array).
        input: ``motor_torque`` or ``table_torque`` (:func:`state_space`'s inputs).
        output: ``table_over_motor`` — the paper's ratio X_θt / (X_θm·Rg·Rw), the
            gain of ``rtid experiment frequency-response --linear`` (1 at low
            frequency, peaks at the motor-held modes); ``motor_compliance`` — the
            motor angle over its torque, rad/(N·m); or a state of
            :func:`state_space` (``theta_t``, ``theta_t_dot``, …) over the input.
            The two ratios are responses to the motor's torque.

    Returns:
        A complex128 array like `freqs_hz` (a complex number for a number; NaN
        where the solve fails). ``20·log10(abs(h))`` is the gain in dB,
        ``np.angle(h)`` the phase.
    """
    scalar = isinstance(freqs_hz, numbers.Real) and not isinstance(freqs_hz, bool)
    f = _real_array([freqs_hz] if scalar else freqs_hz, "freqs_hz")
    if not isinstance(input, str):
        raise TypeError(f"input: expected a name (motor_torque, table_torque), got {type(input).__name__}")
    if not isinstance(output, str):
        raise TypeError(f"output: expected a name (table_over_motor, …), got {type(output).__name__}")
    h = _rtid.frequency_response(_params_arg(params), f, input, output)
    return h[0] if scalar else h


# --- after an identification: compensate, tune, predict, select ----------------------

from ._commissioning import Compensation, Prediction, Tuning, compensate, predict, select, tune  # noqa: E402
