"""The commissioning chain after an identification: ``compensate`` (backlash and
error table, friction), ``tune`` (the cascade's gains and notches), ``predict`` (their
effect with the fit's uncertainty) and ``select`` (which identification the data
support) — the calls ``rtid compensate``, ``rtid tune``, ``rtid predict`` and
``rtid select`` make, so the numbers are the command line's."""

from __future__ import annotations

import json
import os
import warnings
from collections.abc import Mapping

from . import (
    IdentifyResult,
    Params,
    RtidError,
    _as_experiment,
    _check_parameter_name,
    _choice,
    _finite_number,
    _names,
    _names_list,
    _params_arg,
    _progress,
    _rtid,
    _temporary_folder,
    _whole,
)
from ._experiments import _compensation_text


class Compensation:
    """A compensation: the backlash and error table (and a friction law) an axis's
    controller adds, with what it does to the ISO 230-2 values.

    Attributes:
        summary: ``rtid compensate --json``'s content: ``unit`` (``arcsec`` or ``um``),
            ``backlash``, ``targets`` (each target's x̄↑, x̄↓, reversal and table value),
            ``build`` and ``check`` (the ISO 230-2 axis values before, with the
            backlash only and after, of the runs it was built from and of the others),
            ``friction``, ``warnings``.
        text: compensation.json's text (``rtid compensate -o``), for
            ``run_experiment("positioning", …, compensation=…)``, ``predict`` and the
            command line's ``--compensation``.
        warnings: the warnings' messages (a compensation that does not help the runs
            it was not built from, …).
    """

    def __init__(self, summary: dict, text: str):
        self.summary = summary
        self.text = text
        self.warnings = [w.get("message", "") for w in summary.get("warnings", [])]

    @property
    def axis(self) -> str:
        """``rotary`` or ``linear``."""
        return self.to_dict()["axis"]

    @property
    def backlash(self) -> float:
        """The backlash added while moving down, in ``summary["unit"]``."""
        return self.summary["backlash"]

    def to_dict(self) -> dict:
        """compensation.json's content."""
        return json.loads(self.text)

    def save(self, path) -> None:
        """Writes compensation.json (for ``--compensation`` on the command line)."""
        with open(os.fspath(path), "w", encoding="utf-8") as f:
            f.write(self.text)

    def sinumerik(self, axis_number: int, *, reference: float | None = None) -> str:
        """The SINUMERIK EEC program of the table (``--sinumerik FILE --axis-number N``):
        resampled onto equidistant points, zero at ``reference`` (degrees, or mm on a
        linear axis; default the table's first point)."""
        n = _whole(axis_number, "axis_number")
        scale = 3.141592653589793 / 180.0 if self.axis == "rotary" else 1e-3
        ref = None if reference is None else _finite_number(reference, "reference") * scale
        note = f"rtid {_rtid.VERSION} (Python) compensate {self.summary.get('source', '')}"
        program, _, _ = _rtid.sinumerik_program(self.text, n, ref, note)
        return program

    def csv(self) -> str:
        """The table as CSV (``--csv``): position and value (degrees and arc-seconds,
        or mm and µm)."""
        return _rtid.table_csv(self.text)

    def __reduce__(self):
        return (Compensation, (self.summary, self.text))

    def __repr__(self) -> str:
        u = self.summary.get("unit", "")
        after = (self.summary.get("check") or self.summary["build"])["after"]
        return (f"<rtid.Compensation {self.axis}: backlash {self.backlash:.3g} {u}, "
                f"{len(self.summary['targets'])} targets, A after {after['A']:.3g} {u}>")


def compensate(source, *, runs: str | None = None, friction_map=None, friction: bool = False) -> Compensation:
    """The compensation of an axis (``rtid compensate``): an error table of −x̄↑ at
    each target and a backlash of the mean reversal B̄ from an ISO 230-2 positioning
    record, checked on the runs it was not built from.

    Args:
        source: a positioning record (an :class:`Experiment` or its manifest path), or
            a model (:class:`Params`, e.g. an identification's ``fit.params`` with a
            tuned controller), whose standard ISO 230-2 cycle is run
            (``--fit``/``--preset``).
        runs: build from these runs (``"1-3"``, ``"2"``); the others check it
            (``--runs``; default all, nothing checks it).
        friction_map: add the friction compensation this friction-map experiment
            determines (``--friction-map``).
        friction: with a model: add the friction law of its steady map (``--friction``).

    Returns:
        A :class:`Compensation`. Running the model's cycle is interruptible (Ctrl-C:
        KeyboardInterrupt).
    """
    if runs is not None and not isinstance(runs, str):
        runs = str(_whole(runs, "runs"))
    if not isinstance(friction, bool):
        raise TypeError(f"friction: expected True or False, got {type(friction).__name__}")
    with _temporary_folder() as d:
        if isinstance(source, Params):
            origin = _params_arg(source)
        else:
            exp = _as_experiment(source, "source")
            origin = (exp._written(d), exp.name)
        fmap = None
        if friction_map is not None:
            m = _as_experiment(friction_map, "friction_map")
            fmap = (m._written(d), m.name)
        summary, text = _rtid.compensate(origin, runs, fmap, friction)
    return Compensation(json.loads(summary), text)


class Tuning:
    """A tuning of the cascade (``rtid tune``).

    Attributes:
        params: the tuned parameter set (the model with the proposed settings; today's
            where nothing beats them): :func:`rtid.run_experiment`, ``predict(…,
            tune=…)``, ``Params.with_controller``, ``params.save()`` for ``--tune``.
        before, after: today's settings and the proposed ones (gains, filters,
            margins of the velocity loop alone and of the cascade as it runs).
        proposes: whether the tuning proposes new settings.
        check: the criteria before and after (ISO 230-2 A and R after compensation,
            settling, following error, …); ``warnings`` what got worse.
        summary: ``rtid tune --json``'s content.
    """

    def __init__(self, summary: dict, params: Params):
        self.summary = summary
        self.params = params
        self.before = summary.get("before")
        self.after = summary.get("after")
        self.proposes = bool(summary.get("proposes"))
        self.check = summary.get("check")
        self.warnings = list(summary.get("warnings", []))

    def to_dict(self) -> dict:
        """``rtid tune --json``'s content."""
        return json.loads(json.dumps(self.summary))

    def sinamics(self) -> str:
        """The tuned settings as a commented SINAMICS parameter list (``--sinamics``)."""
        return _rtid.sinamics_settings(_params_arg(self.params), self._closed_loop())

    def sinumerik(self, axis_number: int, *, gear_ratio: tuple | None = None) -> str:
        """The tuned settings as SINUMERIK machine data for axis ``AX<axis_number>``
        (``--sinumerik``; ``gear_ratio=(motor, load)`` revolutions where Rg·Rw is not a
        ratio of whole numbers)."""
        n = _whole(axis_number, "axis_number")
        if gear_ratio is not None:
            if not isinstance(gear_ratio, (tuple, list)) or len(gear_ratio) != 2:
                raise TypeError(f"gear_ratio: expected (motor, load) revolutions, got {gear_ratio!r}")
            gear_ratio = (_whole(gear_ratio[0], "gear_ratio"), _whole(gear_ratio[1], "gear_ratio"))
        return _rtid.sinumerik_settings(_params_arg(self.params), n, gear_ratio, self._closed_loop())

    def _closed_loop(self) -> tuple:
        """The tuned speed loop's equivalent time constant and bandwidth (MD32810)."""
        c = (self.after or {}).get("closed_loop") or {}
        return (c.get("equivalent_time_s"), c.get("speed_bandwidth_hz"))

    def __repr__(self) -> str:
        a = self.after or {}
        state = "proposes" if self.proposes else "keeps today's"
        return (f"<rtid.Tuning {state}: Kvp {a.get('Kvp', float('nan')):.4g}, Kvi {a.get('Kvi', float('nan')):.4g}, "
                f"Kpp {a.get('Kpp', float('nan')):.4g}, {len(a.get('filters', []))} filter(s)>")


def tune(params: Params, *, phase_margin_deg: float = 50.0, gain_margin_db: float = 6.0,
         objective: str = "positioning", loop: str | None = None, max_kpp: float | None = None,
         max_bandwidth_hz: float | None = None, notch_depth_db: float = -20.0,
         notch_min_width: float = 0.2, torque_reserve: float = 0.2, fit=None, vary: dict | None = None,
         delay_periods: int = 0, nominal: bool = False, progress=None) -> Tuning:
    """Tunes the velocity PI, the position gain and notch filters on the nonlinear
    model (``rtid tune``; docs/tuning.md): candidates whose cascade as it runs keeps
    the margins, weighed against today's settings.

    Args:
        params: the model (an identification's ``fit.params``, or a preset).
        phase_margin_deg, gain_margin_db: the targets on the cascade as it runs.
        objective: ``positioning`` (ISO 230-2 A and R after compensation, then
            settling), ``following`` or ``settling``.
        loop: ``semi_closed`` or ``full_closed`` (default the set's).
        max_kpp, max_bandwidth_hz, notch_depth_db, notch_min_width, torque_reserve:
            the limits of the search, as the flags of the same names.
        fit: an identification (:class:`IdentifyResult`, its ``to_dict()``, or a result
            file) whose values are set in ``params`` and whose intervals make the range.
        vary: the machine as it may be, ``{"Jt": (0.5, 2)}``: ratios of each value
            (``--vary``); delay_periods: control periods of delay beyond the model's
            (``--delay-periods``); nominal: the nominal machine alone (``--nominal``).
            Without them the range is the fit's intervals and the held ranges, the four
            that move today's margins most, as ``rtid tune``'s.
        progress: a progress bar of the candidates weighed, as :func:`rtid.identify`'s
            (a function is called as ``progress(done, total)``).

    Returns:
        A :class:`Tuning`. Interruptible: Ctrl-C raises KeyboardInterrupt.
    """
    pm = _finite_number(phase_margin_deg, "phase_margin_deg")
    if not 0 < pm < 180:
        raise RtidError(f"phase_margin_deg: {pm}: a phase margin lies between 0° and 180°")
    gm = _finite_number(gain_margin_db, "gain_margin_db")
    if not 0 <= gm <= 60:
        raise RtidError(f"gain_margin_db: {gm}: a gain margin target lies in 0..60 dB")
    depth = _finite_number(notch_depth_db, "notch_depth_db")
    if not -60 <= depth <= -1:
        raise RtidError(f"notch_depth_db: {depth}: a notch's depth lies in -60..-1 dB")
    width = _finite_number(notch_min_width, "notch_min_width")
    if not 0.01 <= width <= 1:
        raise RtidError(f"notch_min_width: {width}: a fraction of the centre in 0.01..1")
    reserve = _finite_number(torque_reserve, "torque_reserve")
    if not 0 <= reserve <= 0.9:
        raise RtidError(f"torque_reserve: {reserve}: a fraction of the limit in 0..0.9")
    options = {
        "phase_margin_deg": pm, "gain_margin_db": gm,
        "objective": _choice(objective, "objective", _names.OPTIONS["objective"]),
        "loop": None if loop is None else _choice(loop.replace("-", "_") if isinstance(loop, str) else loop,
                                                  "loop", _names.OPTIONS["loop"]),
        "max_kpp": _positive_or_none(max_kpp, "max_kpp"),
        "max_bandwidth_hz": _positive_or_none(max_bandwidth_hz, "max_bandwidth_hz"),
        "notch_depth_db": depth, "notch_min_width": width, "torque_reserve": reserve,
    }
    options.update(_range_options(vary, delay_periods, nominal))
    text = None if fit is None else _fit_json(fit, "fit")
    callback, close = _progress.reporter(progress, "tune", "candidate")
    try:
        summary, tuned = _rtid.tune(_params_arg(params), options, text, callback)
    finally:
        close()
    return Tuning(json.loads(summary), Params(tuned))


def _range_options(vary, delay_periods, nominal) -> dict:
    """``rtid tune``'s --vary, --delay-periods and --nominal, checked."""
    pairs = []
    if vary is not None:
        if not isinstance(vary, Mapping):
            raise TypeError(f"vary: expected a dict {{name: (low, high)}}, got {type(vary).__name__}")
        for name, ratios in vary.items():
            try:
                low, high = ratios
            except (TypeError, ValueError):
                raise RtidError(f"vary: {name}: give (low, high), ratios of the value, e.g. (0.5, 2)") from None
            pairs.append((str(name), _finite_number(low, f"vary: {name}"), _finite_number(high, f"vary: {name}")))
    if isinstance(delay_periods, bool) or not isinstance(delay_periods, int) or delay_periods < 0:
        raise RtidError(f"delay_periods: {delay_periods!r}: a whole number of control periods, 0 or more")
    if nominal and (pairs or delay_periods):
        raise RtidError("nominal: the nominal machine alone, without vary or delay_periods")
    return {"vary": pairs, "delay_periods": delay_periods, "nominal": bool(nominal)}


def _positive_or_none(value, name: str):
    if value is None:
        return None
    v = _finite_number(value, name)
    if not v > 0:
        raise RtidError(f"{name}: {v}: must be a positive number")
    return v


class Prediction:
    """A prediction of the ISO 230-2 values (and the servo's) before and after, with
    intervals from parameter sets drawn from the fit (``rtid predict``).

    Attributes:
        cases: per test and case (``before``, ``after``) each output's value at the
            fit with its interval: ``{"test", "case", "unit", "values": [{"name",
            "nominal", "median", "lower", "upper"}, …]}`` as ``rtid predict --json``.
        source: ``covariance`` or ``bootstrap``; ``drawn`` the parameters drawn.
        completed, asked: draws done and asked for (Ctrl-C stops them early).
        notes: what the intervals rest on.
        interrupted: whether Ctrl-C stopped the draws.
    """

    def __init__(self, summary: dict, interrupted: bool = False):
        self.summary = summary
        self.cases = list(summary.get("cases", []))
        self.source = summary.get("source")
        self.drawn = list(summary.get("drawn", []))
        self.completed = summary.get("completed")
        self.asked = summary.get("asked")
        self.notes = list(summary.get("notes", []))
        self.interrupted = interrupted

    def to_dict(self) -> dict:
        """``rtid predict --json``'s content (``-o``'s file)."""
        return json.loads(json.dumps(self.summary))

    def value(self, test: str, case: str, name: str) -> dict:
        """One output: ``value("positioning", "after", "A")`` → ``{"nominal", "lower",
        "upper", …}``."""
        for c in self.cases:
            if c.get("test") == test and c.get("case") == case:
                for v in c.get("values", []):
                    if v.get("name") == name:
                        return v
        raise KeyError(f"{test}/{case}/{name}: not in the prediction")

    def to_pandas(self):
        """One row per test, case and output: nominal, median, lower, upper, unit."""
        from ._results import _pandas
        pd = _pandas("Prediction.to_pandas()")
        rows = [{"test": c.get("test"), "case": c.get("case"), "output": v.get("name"),
                 "nominal": v.get("nominal"), "median": v.get("median"), "lower": v.get("lower"),
                 "upper": v.get("upper"), "unit": c.get("unit")}
                for c in self.cases for v in c.get("values", [])]
        return pd.DataFrame(rows).set_index(["test", "case", "output"])

    def __repr__(self) -> str:
        stopped = ", interrupted" if self.interrupted else ""
        return (f"<rtid.Prediction {len(self.cases)} case(s) from {self.completed} of {self.asked} "
                f"{self.source} draws{stopped}>")


def _fit_json(fit, argument: str) -> str:
    """An identification result's JSON: an :class:`IdentifyResult`, its dict, or a
    result file's path."""
    if isinstance(fit, IdentifyResult):
        return json.dumps(fit.to_dict())
    if isinstance(fit, Mapping):
        return json.dumps(dict(fit))
    if isinstance(fit, (str, os.PathLike)):
        with open(fit, encoding="utf-8-sig") as f:
            return f.read()
    raise TypeError(f"{argument}: expected an rtid.IdentifyResult, its to_dict() or a result file's path, "
                    f"got {type(fit).__name__}")


def predict(fit, params: Params | None = None, *, compensation=None, tune=None,
            tests="positioning", draws: int = 50, from_: str | None = None, hold=(),
            uncertain: dict | None = None, runs: int = 5, level: float = 0.95, seed: int = 1,
            progress=None) -> Prediction:
    """The effect of a compensation and a tuning predicted on the identified model,
    with the fit's uncertainty carried through (``rtid predict``; docs/compensation.md).

    Args:
        fit: the identification (:class:`IdentifyResult`, its ``to_dict()``, or a
            result file ``rtid identify --out`` wrote).
        params: the base the fit started from (its values are set in it); default
            ``fit.params``.
        compensation: a :class:`Compensation` (its dict, a compensation.json path).
        tune: a tuned set (:class:`Tuning` or its ``params``): its controller settings.
        tests: ``positioning`` and/or ``servo`` (a list or ``"positioning,servo"``).
        draws: normal draws (``--draws``); from_: ``covariance`` or ``bootstrap``
            (default the bootstrap where the fit has replicates); hold: fitted
            parameters held at their values; uncertain: held parameters' relative
            half-ranges, ``{"Kw": 0.1}``; runs: positioning runs per direction; level:
            the central interval's probability; seed: of the draws.
        progress: a progress bar of the draws, as :func:`rtid.identify`'s (a function
            is called as ``progress(done, total)``).

    Returns:
        A :class:`Prediction`. Ctrl-C stops the draws: the prediction is made from
        those done (``interrupted``, a RuntimeWarning).
    """
    text = _fit_json(fit, "fit")
    if params is None:
        if not isinstance(fit, IdentifyResult):
            raise RtidError("params: give the base the fit started from (a result file has no parameter set)")
        params = fit.params
    if isinstance(tune, _TUNING_TYPES):
        tune = tune.params
    if tune is not None and not isinstance(tune, Params):
        raise TypeError(f"tune: expected an rtid.Tuning or its params, got {type(tune).__name__}")
    tests = [tests] if isinstance(tests, str) and "," not in tests else _names_list(tests, "tests")
    for t in tests:
        _choice(t.strip(), "tests", ("positioning", "servo"))
    held = _names_list(hold, "hold", allow_empty=True)
    for name in held:
        _check_parameter_name(name, "hold")
    if uncertain is not None and not isinstance(uncertain, Mapping):
        raise TypeError(f"uncertain: expected a dict {{name: relative half-range}}, got {type(uncertain).__name__}")
    for name in uncertain or {}:
        _check_parameter_name(name, "uncertain")
    lv = _finite_number(level, "level")
    if not 0 < lv < 1:
        raise RtidError(f"level: {lv}: a probability in (0, 1)")
    options = {
        "compensation": None if compensation is None else _compensation_text(compensation),
        "tune": None if tune is None else _params_arg(tune),
        "tests": [t.strip() for t in tests],
        "draws": _whole(draws, "draws"),
        "from_": None if from_ is None else _choice(from_, "from_", ("covariance", "bootstrap")),
        "hold": held,
        "uncertain": [(n, _finite_number(h, f"uncertain[{n}]")) for n, h in (uncertain or {}).items()],
        "runs": _whole(runs, "runs"),
        "level": lv,
        "seed": _whole(seed, "seed", 0),
    }
    callback, close = _progress.reporter(progress, "predict", "draw")
    try:
        summary, stopped = _rtid.predict(text, _params_arg(params), options, callback)
    finally:
        close()
    result = Prediction(json.loads(summary), stopped)
    if stopped:
        warnings.warn("rtid.predict: interrupted; the prediction is made from the draws done",
                      RuntimeWarning, stacklevel=2)
    return result


_TUNING_TYPES = (Tuning,)


def select(*fits, labels=None) -> dict:
    """Which of several identifications of the same data the data support
    (``rtid select --json``): AIC, AICc, BIC, Akaike weights, and F-tests of nested
    fits.

    Args:
        *fits: two or more identifications (:class:`IdentifyResult`, their dicts or
            result files) of the same experiments, objectives and weights.
        labels: a name for each (default ``fit 1``, ``fit 2``, … or the file paths).

    Returns:
        A dict: ``candidates`` ranked (``label``, ``fitted``, ``n``, ``k``, ``cost``,
        ``aic``, ``aicc``, ``bic``, ``delta``, ``weight``), ``nested`` (the F-tests),
        ``criterion``.
    """
    if len(fits) == 1 and isinstance(fits[0], (list, tuple)):
        fits = tuple(fits[0])
    if labels is None:
        labels = [os.fspath(f) if isinstance(f, (str, os.PathLike)) else f"fit {i + 1}"
                  for i, f in enumerate(fits)]
    labels = _names_list(list(labels), "labels", allow_empty=True)
    if len(labels) != len(fits):
        raise RtidError(f"labels: {len(labels)} labels for {len(fits)} fits: give one per fit")
    pairs = [(label, _fit_json(f, f"fits[{i}]")) for i, (label, f) in enumerate(zip(labels, fits))]
    return json.loads(_rtid.select(pairs))


__all__ = ["Compensation", "compensate", "Tuning", "tune", "Prediction", "predict", "select"]
