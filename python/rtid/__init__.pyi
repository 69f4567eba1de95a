"""Type stubs of rtid's Python module (docstrings in rtid/__init__.py)."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal, Union

import numpy as np
import numpy.typing as npt

VERSION: str

class RtidError(ValueError): ...

_Path = Union[str, os.PathLike[str]]
_Floats = npt.ArrayLike

class Params(Mapping[str, float]):
    def __getitem__(self, name: str) -> float: ...
    def __setitem__(self, name: str, value: float) -> None: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def __contains__(self, name: object) -> bool: ...
    @property
    def name(self) -> str: ...
    @property
    def topology(self) -> str: ...
    @property
    def axis(self) -> str: ...
    def describe(self) -> dict[str, dict[str, Any]]: ...
    def to_json(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    def copy(self) -> Params: ...
    @property
    def loop(self) -> Literal["semi_closed", "full_closed"]: ...
    @loop.setter
    def loop(self, mode: Literal["semi_closed", "full_closed"]) -> None: ...
    @property
    def filters(self) -> list[dict[str, Any]]: ...
    @filters.setter
    def filters(self, filters: Sequence[Mapping[str, Any]]) -> None: ...
    def with_controller(self, tuned: Params | Tuning) -> Params: ...
    def __copy__(self) -> Params: ...
    def __deepcopy__(self, memo: Any) -> Params: ...

def params(preset: str | None = None, *, path: _Path | None = None, **overrides: float) -> Params: ...
def preset_names() -> list[str]: ...
def modes(params: Params) -> dict[str, Any]: ...
def simulate(
    params: Params,
    input: str | _Path | _Floats,
    duration_s: float,
    *,
    time_s: _Floats | None = None,
    dt_s: float | None = None,
    sample_s: float = 1e-4,
    load_nm: float = 0.0,
) -> dict[str, npt.NDArray[np.float64]]: ...

_Compensation = Union["Compensation", Mapping[str, Any], _Path]

@dataclass
class Channel:
    name: str
    unit: str
    samples: npt.NDArray[Any]
    abscissa: npt.NDArray[np.float64] | None = None
    abscissa_unit: str = ""

@dataclass
class Recording:
    format: str
    channels: dict[str, Channel]
    notes: list[str]

def import_file(path: _Path) -> Recording: ...

class Experiment:
    manifest: dict[str, Any]
    columns: dict[str, npt.NDArray[np.float64]] | None
    path: str | None
    name: str
    @property
    def kind(self) -> str: ...

def experiment(
    kind: str,
    *,
    conditions: dict[str, Any] | None = None,
    mechanism: str | None = None,
    notes: str | None = None,
    name: str | None = None,
    **columns: _Floats,
) -> Experiment: ...
def read_experiment(path: _Path) -> Experiment: ...
def run_experiment(
    kind: Literal["frequency_response", "frequency-response", "torque_curve", "torque-curve",
                  "fluctuation", "unbalance", "positioning", "friction_map", "friction-map",
                  "servo_trace", "servo-trace", "frequency_response_time", "frequency-response-time"],
    params: Params,
    **settings: Any,
) -> Experiment: ...
def evaluate(
    experiment: Experiment | _Path,
    params: Params | None = None,
    *,
    runs: str | int | None = None,
    compensation: _Compensation | None = None,
    segment_s: float | None = None,
    min_coherence: float | None = None,
    settle_fraction: float | None = None,
    cutoff_hz: float | None = None,
    decimation: int | None = None,
    trim_s: float | None = None,
    min_speed: float | None = None,
) -> dict[str, Any]: ...

@dataclass
class Curve:
    experiment: str
    quantity: str
    unit: str
    abscissa_name: str
    abscissa_unit: str
    abscissa: npt.NDArray[np.float64]
    measured: npt.NDArray[np.float64]
    model: npt.NDArray[np.float64]
    residual: npt.NDArray[np.float64] | None = None
    model_start: npt.NDArray[np.float64] | None = None
    model_abscissa: npt.NDArray[np.float64] | None = None

class IdentifyResult:
    values: dict[str, float]
    initial: dict[str, float]
    bounds: dict[str, tuple[float, float]]
    standard_errors: dict[str, float]
    names: list[str]
    correlation: npt.NDArray[np.float64]
    covariance: npt.NDArray[np.float64]
    intervals: dict[str, tuple[float | None, float | None]]
    interval_method: Literal["profile", "bootstrap", "standard errors"]
    profiles: dict[str, dict[str, Any]] | None
    resampling: dict[str, Any] | None
    warnings: list[dict[str, str]]
    interrupted: bool
    cost: float | None
    ndata: int | None
    nvarys: int
    chisqr: float | None
    redchi: float | None
    aic: float | None
    aicc: float | None
    bic: float | None
    nfev: int | None
    held: list[dict[str, Any]]
    termination: dict[str, Any]
    success: bool
    message: str
    curves: list[Curve]
    params: Params
    def to_dict(self) -> dict[str, Any]: ...
    def correlations(self, threshold: float = 0.1) -> list[tuple[str, str, float]]: ...
    def report(self, min_correl: float = 0.1) -> str: ...
    def to_pandas(self, table: Literal["parameters", "covariance", "correlation"] = "parameters") -> Any: ...
    def _repr_html_(self) -> str: ...

def identify(
    experiments: Experiment | _Path | Sequence[Experiment | _Path],
    params: Params,
    fit: str | Sequence[str] | None = None,
    *,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    method: Literal["lsq", "lm", "nelder-mead", "pso"] | None = None,
    model: Literal["auto", "linear", "nonlinear"] = "auto",
    starts: int | None = None,
    seed: int = 1,
    max_iters: int = 50,
    start: Literal["estimate", "given"] = "estimate",
    weights: Sequence[float] | None = None,
    objectives: Sequence[str] | None = None,
    profile: bool | str | Sequence[str] | None = None,
    resample: int | None = None,
    uncertain: Mapping[str, float] | None = None,
    intervals: Literal["auto", "standard-errors", "bootstrap"] = "auto",
    joint: bool = False,
    checkpoint: _Path | None = None,
    resume: bool = False,
    progress: bool | Callable[..., object] | None = None,
) -> IdentifyResult: ...

@dataclass
class SweepResult:
    factors: list[str]
    design: npt.NDArray[np.float64]
    output_columns: list[str]
    outputs: npt.NDArray[np.float64]
    index: npt.NDArray[np.uint64]
    indices: dict[str, Any]
    def column(self, name: str) -> npt.NDArray[np.float64]: ...
    def to_pandas(self) -> Any: ...
    def indices_to_pandas(self) -> Any: ...

def sweep(
    params: Params,
    vary: str | Sequence[str],
    outputs: str | Sequence[str],
    *,
    method: Literal["grid", "local", "morris", "sobol"] = "grid",
    samples: int = 256,
    bootstrap: int = 500,
    trajectories: int = 20,
    levels: int = 4,
    step: float = 0.01,
    seed: int = 0,
    tests: Literal["short", "full"] = "short",
    out: _Path | None = None,
    resume: bool = False,
    progress: bool | Callable[..., object] | None = None,
) -> SweepResult: ...

@dataclass
class StateSpace:
    A: npt.NDArray[np.float64]
    B: npt.NDArray[np.float64]
    C: npt.NDArray[np.float64]
    D: npt.NDArray[np.float64]
    states: list[str]
    inputs: list[str]
    outputs: list[str]
    def __iter__(self) -> Iterator[npt.NDArray[np.float64]]: ...

def state_space(params: Params) -> StateSpace: ...
def frequency_response(
    params: Params,
    freqs_hz: float | _Floats,
    *,
    input: Literal["motor_torque", "table_torque"] = "motor_torque",
    output: str = "table_over_motor",
) -> complex | npt.NDArray[np.complex128]: ...

class Compensation:
    summary: dict[str, Any]
    text: str
    warnings: list[str]
    @property
    def axis(self) -> Literal["rotary", "linear"]: ...
    @property
    def backlash(self) -> float: ...
    def to_dict(self) -> dict[str, Any]: ...
    def save(self, path: _Path) -> None: ...
    def sinumerik(self, axis_number: int, *, reference: float | None = None) -> str: ...
    def csv(self) -> str: ...

def compensate(
    source: Experiment | _Path | Params,
    *,
    runs: str | int | None = None,
    friction_map: Experiment | _Path | None = None,
    friction: bool = False,
) -> Compensation: ...

class Tuning:
    summary: dict[str, Any]
    params: Params
    before: dict[str, Any] | None
    after: dict[str, Any] | None
    proposes: bool
    check: dict[str, Any] | None
    warnings: list[Any]
    def to_dict(self) -> dict[str, Any]: ...
    def sinamics(self) -> str: ...
    def sinumerik(self, axis_number: int, *, gear_ratio: tuple[int, int] | None = None) -> str: ...

def tune(
    params: Params,
    *,
    phase_margin_deg: float = 50.0,
    gain_margin_db: float = 6.0,
    objective: Literal["positioning", "following", "settling"] = "positioning",
    loop: Literal["semi_closed", "full_closed"] | None = None,
    max_kpp: float | None = None,
    max_bandwidth_hz: float | None = None,
    notch_depth_db: float = -20.0,
    notch_min_width: float = 0.2,
    torque_reserve: float = 0.2,
    fit: IdentifyResult | Mapping[str, Any] | str | os.PathLike[str] | None = None,
    vary: Mapping[str, tuple[float, float]] | None = None,
    delay_periods: int = 0,
    nominal: bool = False,
    progress: bool | Callable[..., object] | None = None,
) -> Tuning: ...

class Prediction:
    summary: dict[str, Any]
    cases: list[dict[str, Any]]
    source: str | None
    drawn: list[str]
    completed: int | None
    asked: int | None
    notes: list[str]
    interrupted: bool
    def to_dict(self) -> dict[str, Any]: ...
    def value(self, test: str, case: str, name: str) -> dict[str, Any]: ...
    def to_pandas(self) -> Any: ...

def predict(
    fit: IdentifyResult | Mapping[str, Any] | _Path,
    params: Params | None = None,
    *,
    compensation: _Compensation | None = None,
    tune: Tuning | Params | None = None,
    tests: str | Sequence[str] = "positioning",
    draws: int = 50,
    from_: Literal["covariance", "bootstrap"] | None = None,
    hold: Sequence[str] = (),
    uncertain: Mapping[str, float] | None = None,
    runs: int = 5,
    level: float = 0.95,
    seed: int = 1,
    progress: bool | Callable[..., object] | None = None,
) -> Prediction: ...

def select(
    *fits: IdentifyResult | Mapping[str, Any] | _Path,
    labels: Sequence[str] | None = None,
) -> dict[str, Any]: ...
