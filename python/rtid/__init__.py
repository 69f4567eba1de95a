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
file, line, column or parameter at fault); bad arguments (NaN, wrong length or dtype,
an unknown parameter) raise it naming the argument.
"""

from __future__ import annotations

import json
import math
import numbers
import os
import tempfile
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from . import _rtid
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
    "evaluate",
    "IdentifyResult",
    "identify",
    "SweepResult",
    "sweep",
]


# --- parameters -------------------------------------------------------------------


def _finite_number(value, argument: str) -> float:
    """`value` as a float, or a ValueError naming `argument`."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise RtidError(f"{argument}: {value!r} is not a number (SI units)")
    v = float(value)
    if not math.isfinite(v):
        raise RtidError(f"{argument}: {v} is not a finite number")
    return v


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
        self._inner[name] = _finite_number(value, name)

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

    def __repr__(self) -> str:
        return f"<rtid.Params {self.name!r}: {self.topology}, {self.axis}, {len(self)} parameters>"


def params(preset: str | None = None, *, path=None, **overrides) -> Params:
    """The parameter set of a preset or a parameter file, with overrides.

    Args:
        preset: a shipped preset (:func:`preset_names`: ``worm-gear``,
            ``roller-gear-cam``, …), like ``--preset``.
        path: a parameter file (JSON), like ``--params``; not with ``preset``.
        **overrides: ``NAME=VALUE`` in SI units, like ``--set NAME=VALUE``.

    Raises:
        RtidError: an unknown preset or parameter, a value outside its constraint.
    """
    pairs = [(name, _finite_number(v, name)) for name, v in overrides.items()]
    return Params(
        _rtid.load_params(preset, None if path is None else os.fspath(path), pairs)
    )


def preset_names() -> list:
    """The names of the shipped presets."""
    return list(_rtid.preset_names())


def _params_arg(p) -> object:
    if not isinstance(p, Params):
        raise RtidError(f"params: expected an rtid.Params (rtid.params(...)), got {type(p).__name__}")
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
    a = np.asarray(values)
    if a.dtype == object or a.dtype.kind not in "iuf":
        raise RtidError(f"{argument}: dtype {a.dtype} is not a real number type (give float64)")
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
        ``table_angle_rad``, ``table_velocity_rad_s``, …) and for a ``move:``
        ``reference_rad``. The kernel runs with the GIL released.
    """
    duration_s = _finite_number(duration_s, "duration_s")
    sample_s = _finite_number(sample_s, "sample_s")
    load_nm = _finite_number(load_nm, "load_nm")
    if dt_s is not None:
        dt_s = _finite_number(dt_s, "dt_s")
    p = _params_arg(params)
    if isinstance(input, (str, os.PathLike)):
        return dict(_rtid.simulate(p, duration_s, os.fspath(input), None, None, dt_s, sample_s, load_nm))
    torque = _real_array(input, "input")
    if time_s is None:
        t = np.arange(torque.size, dtype=np.float64) * sample_s
    else:
        t = _real_array(time_s, "time_s")
        if t.size != torque.size:
            raise RtidError(f"input: {torque.size} torques for {t.size} times in time_s: give one torque per time")
    return dict(_rtid.simulate(p, duration_s, None, torque, t, dt_s, sample_s, load_nm))


# --- files labs export --------------------------------------------------------------


@dataclass
class Channel:
    """One channel of a recording: samples (float64, or complex128 for a complex
    channel), the unit as the file spells it, and the abscissa when the file gives
    one (an array of times or frequencies in ``abscissa_unit``)."""

    name: str
    unit: str
    samples: np.ndarray
    abscissa: np.ndarray | None = None
    abscissa_unit: str = ""


@dataclass
class Recording:
    """What a reader found in one file: its format, channels by name, notes."""

    format: str
    channels: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)


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
        names = list(self.columns)
        table = np.column_stack([self.columns[n] for n in names])
        np.savetxt(base + ".csv", table, fmt="%.17g", delimiter=",", header=",".join(names), comments="")
        manifest = dict(self.manifest, data=os.path.basename(base) + ".csv")
        with open(base + ".json", "w", encoding="utf-8") as f:
            json.dump(manifest, f)
        return base + ".json"

    def __repr__(self) -> str:
        return f"<rtid.Experiment {self.kind} {self.name!r}>"


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
        raise RtidError(f"kind: expected a name such as 'servo_trace', got {kind!r}")
    if not columns:
        raise RtidError("columns: no data column given (e.g. time_s=..., force_n=...)")
    arrays = {n: _real_array(v, n) for n, v in columns.items()}
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
    with tempfile.TemporaryDirectory(prefix="rtid-") as d:
        _rtid.read_experiment(exp._written(d))
    return exp


def read_experiment(path) -> Experiment:
    """An experiment file (a JSON manifest with its CSV), read and checked by rtid."""
    path = os.fspath(path)
    _rtid.read_experiment(path)
    with open(path, encoding="utf-8-sig") as f:
        manifest = json.load(f)
    return Experiment(manifest, None, path, path)


def _as_experiment(e, argument: str) -> Experiment:
    if isinstance(e, Experiment):
        return e
    if isinstance(e, (str, os.PathLike)):
        return read_experiment(e)
    raise RtidError(f"{argument}: expected an rtid.Experiment or a manifest path, got {type(e).__name__}")


def evaluate(experiment, params: Params | None = None) -> dict:
    """The statistics ``rtid evaluate --json`` gives of an experiment, as a dict: the
    resonances (and with the phase the modes) of a frequency response, a torque
    curve's friction and reversals, a positioning record's ISO 230-2 values, the
    friction laws of a friction map, a servo trace's friction law by IDIM-LS (with
    ``params``, at the motor of a geared model, and the trace replayed on the model:
    ``simulation_error``, as ``--params``), a fluctuation or unbalance test's
    deviations in arc-seconds. (Raw time records and the paper's resonance lists:
    the command line for now.)"""
    exp = _as_experiment(experiment, "experiment")
    p = None if params is None else _params_arg(params)
    with tempfile.TemporaryDirectory(prefix="rtid-") as d:
        return json.loads(_rtid.evaluate(exp._written(d), exp.name, p))


# --- identification ---------------------------------------------------------------


class IdentifyResult:
    """An identification's result.

    Attributes:
        values: identified value of each fitted parameter (SI).
        initial: where the search started.
        standard_errors: each fitted parameter's standard error (SI), where the
            Jacobian gives one.
        names: the order of ``correlation``'s rows.
        correlation: the fitted parameters' correlation matrix (float64 array).
        intervals: ``(low, high)`` of each at 95 %: the profile's where ``profile``
            was asked (an end the data do not bound is ``None``), else the
            bootstrap's where ``resample`` was, else ± 1.96 standard errors.
        interval_method: ``"profile"``, ``"bootstrap"`` or ``"standard errors"``.
        profiles: the profiles as the result file holds them (``None`` if not asked).
        resampling: the bootstrap as the result file holds it (``None`` if not asked).
        warnings: each ``{"code", "message"}`` rtid raised (what the data cannot tell).
        interrupted: whether Ctrl-C ended the search (the best point so far).
        params: the complete identified parameter set.
    """

    def __init__(self, result: dict, identified: Params):
        self._result = result
        self.values = dict(result["parameters"])
        self.initial = dict(result.get("initial", {}))
        u = result.get("uncertainty") or {}
        self.standard_errors = dict((n, v) for n, v in u.get("standard_errors", []) if v is not None)
        self.names = list(u.get("names", []))
        self.correlation = np.array(u.get("correlation", []), dtype=np.float64).reshape(len(self.names), len(self.names))
        self.profiles = result.get("profiles")
        self.resampling = result.get("resampling")
        if self.profiles:
            self.interval_method = "profile"
            self.intervals = {n: (p.get("lower"), p.get("upper")) for n, p in self.profiles.items()}
        elif self.resampling and self.resampling.get("intervals"):
            self.interval_method = "bootstrap"
            self.intervals = {n: (i["lower"], i["upper"])
                              for n, i in self.resampling["intervals"].items()}
        else:
            self.interval_method = "standard errors"
            self.intervals = {
                n: (self.values[n] - 1.96 * se, self.values[n] + 1.96 * se)
                for n, se in self.standard_errors.items()
            }
        self.warnings = list(result.get("warnings", []))
        self.interrupted = bool(result.get("interrupted", False))
        self.cost = result.get("cost")
        self.params = identified

    def to_dict(self) -> dict:
        """The result file's content (``rtid identify --out``'s JSON, without the
        provenance and the comparisons the command line adds)."""
        return json.loads(json.dumps(self._result))

    def __repr__(self) -> str:
        body = ", ".join(f"{n}={v:.6g}" for n, v in self.values.items())
        return f"<rtid.IdentifyResult {body}{' (interrupted)' if self.interrupted else ''}>"


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


def _count(n, name: str) -> int:
    """A positive whole number argument, or a ValueError naming it."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise RtidError(f"{name}: {n!r} is not a positive whole number")
    return int(n)


def identify(experiments, params: Params, fit=None, *, bounds: dict | None = None,
             method: str | None = None, model: str = "auto", starts: int | None = None,
             seed: int = 1, max_iters: int = 50, start: str = "estimate",
             weights=None, objectives=None, profile=None,
             resample: int | None = None) -> IdentifyResult:
    """Identifies parameters from experiments (``rtid identify``).

    Args:
        experiments: an :class:`Experiment` or manifest path, or a list of them.
        params: the parameter set the others stay at (:func:`params`).
        fit: names of the parameters to fit (default: what the experiments determine).
        bounds: ``{"Kw": (1e5, 1e7)}``, SI (``--bound``).
        method: ``lsq``, ``lm``, ``nelder-mead`` or ``pso`` (``--method``).
        model: ``auto``, ``linear`` or ``nonlinear`` (``--model``).
        starts, seed, max_iters, start, weights, objectives: as the flags of the
            same names.
        profile: names to profile (``True``: every fitted parameter), for intervals
            that hold where the cost is not a bowl (``--profile``).
        resample: bootstrap replicates of the residuals' blocks (``--resample``).

    Ctrl-C (KeyboardInterrupt, a notebook's interrupt) ends the search: the best point
    so far is returned, ``interrupted`` set and a warning issued. The search runs with
    the GIL released.
    """
    if isinstance(experiments, (Experiment, str, os.PathLike)):
        experiments = [experiments]
    exps = [_as_experiment(e, f"experiments[{i}]") for i, e in enumerate(experiments)]
    if isinstance(fit, str):
        fit = [n for n in fit.split(",")]
    options = {
        "fit": list(fit or []),
        "bounds": [(n, _finite_number(lo, f"bounds[{n}]"), _finite_number(hi, f"bounds[{n}]"))
                   for n, (lo, hi) in (bounds or {}).items()],
        "method": method,
        "fidelity": model,
        "starts": starts,
        "seed": seed,
        "max_iters": max_iters,
        "start": start,
        "weights": None if weights is None else [_finite_number(w, "weights") for w in weights],
        "objectives": None if objectives is None else list(objectives),
        "profile": _profile_names(profile),
        "resample": None if resample is None else _count(resample, "resample"),
    }
    with tempfile.TemporaryDirectory(prefix="rtid-") as d:
        paths = [(e._written(d), e.name) for e in exps]
        text, identified = _rtid.identify(paths, _params_arg(params), options)
    result = IdentifyResult(json.loads(text), Params(identified))
    if result.interrupted:
        warnings.warn("rtid.identify: interrupted; the result is the best point so far", RuntimeWarning, stacklevel=2)
    return result


# --- sweeps -----------------------------------------------------------------------


@dataclass
class SweepResult:
    """A sweep's design and outputs, row i for design point ``index[i]``.

    Attributes:
        factors: the varied parameters (columns of ``design``).
        design: parameter values, SI (points × factors).
        output_columns: the names of ``outputs``' columns.
        outputs: the outputs at each point (points × columns; NaN where a point
            failed).
        index: each row's design point.
        indices: the sensitivity indices (local, Morris, Sobol; ``rows`` per factor
            and output, ``columns`` naming their values) as ``rtid sweep`` writes them.
    """

    factors: list
    design: np.ndarray
    output_columns: list
    outputs: np.ndarray
    index: np.ndarray
    indices: dict

    def column(self, name: str) -> np.ndarray:
        """The output column `name`."""
        return self.outputs[:, self.output_columns.index(name)]


def sweep(params: Params, vary, outputs, *, method: str = "grid", samples: int = 256,
          bootstrap: int = 500, trajectories: int = 20, levels: int = 4, step: float = 0.01,
          seed: int = 0, tests: str = "short", out=None) -> SweepResult:
    """A sensitivity sweep (``rtid sweep``).

    Args:
        params: the base parameter set.
        vary: ``NAME=LOW..HIGH[:log][:LEVELS]`` specifications, e.g.
            ``["Kw=1e5..1e6:log:20"]`` (a single string is one).
        outputs: what to compute at each point, e.g. ``["resonances"]``.
        method: ``grid``, ``local``, ``morris`` or ``sobol``, with ``samples``,
            ``bootstrap``, ``trajectories``, ``levels``, ``step``, ``seed``,
            ``tests`` as the flags of the same names.
        out: the sweep CSV to keep (default: a temporary file, removed).
    """
    vary = [vary] if isinstance(vary, str) else list(vary)
    outputs = [outputs] if isinstance(outputs, str) else list(outputs)
    options = dict(vary=vary, outputs=outputs, method=method, samples=samples, bootstrap=bootstrap,
                   trajectories=trajectories, levels=levels, step=_finite_number(step, "step"),
                   seed=seed, tests=tests)
    with tempfile.TemporaryDirectory(prefix="rtid-") as d:
        path = os.fspath(out) if out is not None else os.path.join(d, "sweep.csv")
        r = _rtid.sweep(_params_arg(params), options, path)
    return SweepResult(list(r["factors"]), r["design"], list(r["output_columns"]), r["outputs"],
                       r["index"], json.loads(r["indices_json"]))
