"""The result objects of an identification and a sweep: plain Python data (they
pickle and deep-copy), with text and HTML reports and pandas tables for notebooks."""

from __future__ import annotations

import html
import json
import math
from dataclasses import dataclass

import numpy as np

_Z95 = 1.96


def _pandas(what: str):
    """pandas, imported only when a table is asked for."""
    try:
        import pandas
    except ImportError as e:
        raise ImportError(f"{what} needs pandas, which is not installed: pip install pandas") from e
    return pandas


def _name_and_unit(label: str) -> tuple:
    """``"motor torque, N·m"`` as ``("motor torque", "N·m")``."""
    name, _, unit = label.rpartition(", ")
    return (name, unit) if name else (label, "")


@dataclass(repr=False)
class Curve:
    """One experiment's data beside the identified model, in the experiment's axes.

    Attributes:
        experiment: the experiment's name.
        quantity, unit: what ``measured`` and ``model`` are (``"motor torque"``,
            ``"N·m"``; a frequency response: ``"gain"``, ``"dB"``).
        abscissa_name, abscissa_unit: what ``abscissa`` is (``"time"``, ``"s"``).
        abscissa: the measured points' abscissae (float64 array).
        measured: the data there.
        model: the model at the identified values there (a frequency response: the
            linear model's gain; a servo trace: the trace replayed on the model).
        residual: ``measured - model``; ``None`` where the model is computed on
            abscissae of its own (an unbalance test's run of the model).
        model_start: the model at the start values (``None`` where not computed).
        model_abscissa: the model's abscissae where they differ from ``abscissa``.
    """

    experiment: str
    quantity: str
    unit: str
    abscissa_name: str
    abscissa_unit: str
    abscissa: np.ndarray
    measured: np.ndarray
    model: np.ndarray
    residual: np.ndarray | None = None
    model_start: np.ndarray | None = None
    model_abscissa: np.ndarray | None = None

    def __repr__(self) -> str:
        return (f"<rtid.Curve {self.experiment!r}: {self.quantity}, {self.unit} over "
                f"{self.abscissa_name}, {self.abscissa.size} points>")


def _curves(comparisons: list) -> list:
    """The extension's comparisons as :class:`Curve` s, one per measured curve."""
    out = []
    for c in comparisons:
        quantity, unit = _name_and_unit(c["y_label"])
        x_name, x_unit = _name_and_unit(c["x_label"])
        by_role = {}
        for k in c["curves"]:
            by_role.setdefault(k["role"], []).append(k)
        for i, m in enumerate(by_role.get("measured", [])):
            fitted = by_role.get("fitted", [])
            start = by_role.get("start", [])
            if i >= len(fitted):
                continue
            f = fitted[i]
            same = f["x"].shape == m["x"].shape and np.array_equal(f["x"], m["x"])
            s = start[i]["y"] if i < len(start) and np.array_equal(start[i]["x"], m["x"]) else None
            suffix = m["label"].partition(", ")[2]
            out.append(Curve(
                experiment=c["source"],
                quantity=f"{quantity} ({suffix})" if suffix else quantity,
                unit=unit, abscissa_name=x_name, abscissa_unit=x_unit,
                abscissa=m["x"], measured=m["y"], model=f["y"],
                residual=m["y"] - f["y"] if same else None,
                model_start=s, model_abscissa=None if same else f["x"],
            ))
    return out


class IdentifyResult:
    """An identification's result.

    Every per-parameter structure — ``names``, ``values``, ``initial``,
    ``standard_errors``, ``intervals``, ``bounds``, the rows and columns of
    ``correlation`` and ``covariance``, ``to_pandas()``'s rows — is in one order, the
    fit's (``names``).

    Attributes:
        names: the fitted parameters, in the fit's order.
        values: identified value of each fitted parameter (SI).
        initial: where the search started.
        standard_errors: each fitted parameter's standard error (SI); NaN where the
            data do not determine it (rtid then warns).
        correlation: the fitted parameters' correlation matrix (float64 array, rows
            and columns in ``names``' order; NaN for an undetermined parameter).
        covariance: their covariance matrix, SI (standard errors × correlation; NaN
            where a standard error is undefined).
        intervals: ``(low, high)`` of each at 95 %: the profile's where ``profile``
            was asked (an end the data do not bound is ``None``), else the
            bootstrap's where ``resample`` was, else ± 1.96 standard errors.
        interval_method: ``"profile"``, ``"bootstrap"`` or ``"standard errors"``.
        bounds: each fitted parameter's search bounds ``(low, high)``.
        profiles: the profiles as the result file holds them (``None`` if not asked).
        resampling: the bootstrap as the result file holds it (``None`` if not asked).
        held: each held parameter's range and the fitted parameters' shift across it
            (``uncertain`` without ``resample``), as the result file holds them.
        warnings: each ``{"code", "message"}`` rtid raised (what the data cannot tell).
        cost: the cost at the result, Σ weight · mean(scaled residual²) over the
            experiments (docs/identification.md): the sum of squares of the residual
            vector the search minimises, each experiment's scaled residuals times
            √(weight / count) — lmfit's ``chisqr``.
        ndata, nvarys: the number of residuals (data points: a line with phase
            counts twice) and of fitted parameters.
        chisqr, redchi: the cost, and the cost over ``ndata − nvarys``.
        aic, aicc, bic: ndata·ln(chisqr/ndata) + 2·nvarys, its small-sample
            correction (``None`` where ndata ≤ nvarys + 1), ndata·ln(chisqr/ndata) +
            nvarys·ln(ndata) — lmfit's definitions and ``rtid select``'s numbers.
        nfev: the cost evaluations.
        termination: how the search ended, ``{"code", "message", …}``.
        success: whether the search converged — the solver's test met (or its
            target cost reached), or the nonlinear corrections settled — and was
            not interrupted; an iteration limit is not a success.
        message: the termination's message.
        interrupted: whether Ctrl-C ended the work: the search (the best point so
            far; no intervals) or the intervals after it (those finished).
        curves: each experiment's data beside the model (:class:`Curve`).
        params: the complete identified parameter set.
    """

    def __init__(self, result: dict, identified, comparisons: list | None = None,
                 stopped: bool = False, statistics: dict | None = None):
        self._result = result
        u = result.get("uncertainty") or {}
        self.names = list(u.get("names") or result["parameters"])
        self.names += [n for n in result["parameters"] if n not in self.names]
        ordered = lambda d: {n: d[n] for n in self.names if n in d}  # noqa: E731
        self.values = ordered(result["parameters"])
        self.initial = ordered(result.get("initial", {}))
        self.bounds = ordered({n: tuple(b) for n, b in result.get("bounds", {}).items()})
        given = {n: v for n, v in u.get("standard_errors", [])}
        self.standard_errors = {n: math.nan if given.get(n) is None else given[n] for n in self.names}
        n = len(self.names)
        in_result = list(u.get("names", []))
        correlation = np.full((n, n), math.nan)
        if in_result:
            c = np.array(u.get("correlation", []), dtype=np.float64).reshape(len(in_result), len(in_result))
            at = [self.names.index(name) for name in in_result]
            correlation[np.ix_(at, at)] = c
        self.correlation = correlation
        se = np.array([self.standard_errors[name] for name in self.names])
        self.covariance = self.correlation * np.outer(se, se)
        self.profiles = result.get("profiles")
        self.resampling = result.get("resampling")
        self.held = list(result.get("held", []))
        if self.profiles:
            self.interval_method = "profile"
            intervals = {n: (p.get("lower"), p.get("upper")) for n, p in self.profiles.items()}
        elif self.resampling and self.resampling.get("intervals"):
            self.interval_method = "bootstrap"
            intervals = {n: (i["lower"], i["upper"]) for n, i in self.resampling["intervals"].items()}
        else:
            self.interval_method = "standard errors"
            intervals = {
                n: (self.values[n] - _Z95 * se, self.values[n] + _Z95 * se)
                for n, se in self.standard_errors.items() if math.isfinite(se)
            }
        self.intervals = ordered(intervals)
        self.warnings = list(result.get("warnings", []))
        self.interrupted = bool(result.get("interrupted", False) or stopped)
        self.cost = result.get("cost")
        statistics = dict(statistics or {})
        self.ndata = statistics.get("ndata")
        self.nvarys = statistics.get("nvarys", len(self.names))
        self.chisqr = statistics.get("chisqr", self.cost)
        self.redchi = statistics.get("redchi")
        self.aic = statistics.get("aic")
        self.aicc = statistics.get("aicc")
        self.bic = statistics.get("bic")
        self.nfev = result.get("evaluations")
        self.termination = dict(result.get("termination") or {})
        self.message = self.termination.get("message", "")
        code = self.termination.get("code")
        converged = (code == "converged"
                     or (code == "corrections" and self.termination.get("converged"))
                     or (code == "solver" and "target cost" in self.termination.get("reason", "").lower()))
        self.success = bool(converged) and not self.interrupted
        self.curves = _curves(comparisons or [])
        self.params = identified

    def to_dict(self) -> dict:
        """The result file's content (``rtid identify --out``'s JSON, without the
        provenance and the comparisons the command line adds)."""
        return json.loads(json.dumps(self._result))

    def _rows(self) -> list:
        """Each fitted parameter: name, value, standard error, interval, bounds, start, unit."""
        units = {}
        if self.params is not None:
            units = {n: d["unit"] for n, d in self.params.describe().items()}
        rows = []
        for name, value in self.values.items():
            lo, hi = self.intervals.get(name, (None, None))
            b_lo, b_hi = self.bounds.get(name, (None, None))
            rows.append({
                "name": name, "value": value, "stderr": self.standard_errors[name],
                "lower": lo, "upper": hi, "min": b_lo, "max": b_hi,
                "initial": self.initial.get(name), "unit": units.get(name, ""),
            })
        return rows

    def correlations(self, threshold: float = 0.1) -> list:
        """The pairs ``(a, b, r)`` whose correlation's size is above `threshold`,
        largest first."""
        pairs = []
        for i, a in enumerate(self.names):
            for j in range(i + 1, len(self.names)):
                r = self.correlation[i, j]
                if abs(r) > threshold:
                    pairs.append((a, self.names[j], float(r)))
        return sorted(pairs, key=lambda p: -abs(p[2]))

    def report(self, min_correl: float = 0.1) -> str:
        """A text report, as lmfit's ``fit_report``: the fit's statistics (data
        points, variables, χ², reduced χ², AIC, BIC), each parameter with its value,
        standard error, interval, bounds and start, the correlations above
        `min_correl` in size (lmfit's default 0.1), and the warnings."""
        r = self._result
        fmt = lambda v: "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.6g}"  # noqa: E731
        lines = ["[[Fit]]"]
        for key, value in (
            ("experiments", ", ".join(r.get("experiments", []))),
            ("method", f"{r.get('method', '')}, {r.get('fidelity', '')} model"),
            ("evaluations", self.nfev),
            ("termination", f"{self.termination.get('code', '')}: {self.message}"),
            ("success", self.success),
        ):
            lines.append(f"    {key:<13}{value}")
        if self.interrupted:
            lines.append("    interrupted  the best point so far (Ctrl-C)")
        lines.append("[[Fit Statistics]]")
        for key, value in (
            ("data points", self.ndata), ("variables", self.nvarys),
            ("chi-square", fmt(self.chisqr)), ("reduced chi-square", fmt(self.redchi)),
            ("Akaike info crit", fmt(self.aic)), ("AICc", fmt(self.aicc)),
            ("Bayesian info crit", fmt(self.bic)),
        ):
            lines.append(f"    {key:<19}= {value}")
        lines.append(f"[[Parameters]] (intervals 95 %, from {self.interval_method})")
        width = max((len(n) for n in self.values), default=4)
        for row in self._rows():
            se = row["stderr"]
            relative = (f" ({100 * se / abs(row['value']):.2f}%)"
                        if math.isfinite(se) and row["value"] else "")
            shown = fmt(se) if math.isfinite(se) else "(not determined)"
            lines.append(
                f"    {row['name']:<{width}} = {row['value']:.6g} ± {shown}{relative} {row['unit']}"
                f"  [{fmt(row['lower'])}, {fmt(row['upper'])}]"
                f"  bounds [{fmt(row['min'])}, {fmt(row['max'])}]  init {fmt(row['initial'])}"
            )
        pairs = self.correlations(min_correl)
        lines.append(f"[[Correlations]] (|r| > {min_correl:g})")
        lines += [f"    C({a}, {b}) = {c:+.3f}" for a, b, c in pairs] or ["    none"]
        lines.append("[[Warnings]]")
        lines += [f"    {w.get('code')}: {w.get('message', '')}" for w in self.warnings] or ["    none"]
        return "\n".join(lines)

    def to_pandas(self, table: str = "parameters"):
        """A pandas DataFrame: ``"parameters"`` (default) — one row per fitted
        parameter in ``names``' order (index ``name``): value, stderr, lower, upper
        (the 95 % interval), min, max (the bounds), initial, unit; ``"covariance"``
        or ``"correlation"`` — the matrix with rows and columns labelled by
        ``names``. Needs pandas (imported only here)."""
        pd = _pandas("IdentifyResult.to_pandas()")
        if table == "parameters":
            return pd.DataFrame(self._rows()).set_index("name")
        if table in ("covariance", "correlation"):
            labels = pd.Index(self.names, name="parameter")
            return pd.DataFrame(getattr(self, table), index=labels, columns=list(self.names))
        if not isinstance(table, str):
            raise TypeError(f"table: expected a string, got {type(table).__name__}")
        from ._names import unknown
        raise unknown("table", "table", table, ["parameters", "covariance", "correlation"])

    def _repr_html_(self) -> str:
        head = ("<table><thead><tr><th>parameter</th><th>value</th><th>std. error</th>"
                "<th>95 % interval</th><th>bounds</th><th>initial</th><th>unit</th></tr></thead><tbody>")
        fmt = lambda v: "—" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.6g}"  # noqa: E731
        body = "".join(
            f"<tr><td>{html.escape(r['name'])}</td><td>{fmt(r['value'])}</td><td>{fmt(r['stderr'])}</td>"
            f"<td>[{fmt(r['lower'])}, {fmt(r['upper'])}]</td><td>[{fmt(r['min'])}, {fmt(r['max'])}]</td>"
            f"<td>{fmt(r['initial'])}</td><td>{html.escape(r['unit'])}</td></tr>"
            for r in self._rows()
        )
        caption = (f"<p>rtid identification: χ² {fmt(self.chisqr)}, reduced χ² {fmt(self.redchi)}, "
                   f"AIC {fmt(self.aic)}, BIC {fmt(self.bic)}, "
                   f"{html.escape(self.termination.get('code', ''))}"
                   f"{', interrupted' if self.interrupted else ''}; "
                   f"{len(self.warnings)} warning(s)</p>")
        return caption + head + body + "</tbody></table>"

    def __repr__(self) -> str:
        body = ", ".join(f"{n}={v:.6g}" for n, v in self.values.items())
        state = " (interrupted)" if self.interrupted else ("" if self.success else f" ({self.termination.get('code')})")
        return f"<rtid.IdentifyResult {body}{state}>"


@dataclass(repr=False)
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

    def to_pandas(self):
        """The design and outputs as one pandas DataFrame: a row per design point
        (index ``point``), the factors' columns then the outputs'. Needs pandas."""
        pd = _pandas("SweepResult.to_pandas()")
        table = {f: self.design[:, i] for i, f in enumerate(self.factors)}
        table.update({c: self.outputs[:, i] for i, c in enumerate(self.output_columns)})
        return pd.DataFrame(table, index=pd.Index(self.index, name="point"))

    def indices_to_pandas(self):
        """The sensitivity indices in long form: a row per parameter, output and
        statistic (``parameter``, ``output``, ``statistic``, ``value``; ``columns``
        of ``indices`` name the statistics). Empty for a grid. Needs pandas."""
        pd = _pandas("SweepResult.indices_to_pandas()")
        columns = list(self.indices.get("columns", []))
        rows = []
        for r in self.indices.get("rows", []):
            for statistic, value in zip(columns, r.get("values", [])):
                rows.append({"parameter": r.get("parameter"), "output": r.get("output"),
                             "statistic": statistic, "value": math.nan if value is None else value})
        return pd.DataFrame(rows, columns=["parameter", "output", "statistic", "value"])

    def __repr__(self) -> str:
        method = self.indices.get("method", "") if isinstance(self.indices, dict) else ""
        return (f"<rtid.SweepResult{' ' + method if method else ''}: {len(self.index)} points of "
                f"{', '.join(self.factors)} → {len(self.output_columns)} output columns>")
