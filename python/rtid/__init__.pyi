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
                  "fluctuation", "unbalance"],
    params: Params,
    **settings: Any,
) -> Experiment: ...
def evaluate(experiment: Experiment | _Path, params: Params | None = None) -> dict[str, Any]: ...

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
    termination: dict[str, Any]
    success: bool
    message: str
    curves: list[Curve]
    params: Params
    def to_dict(self) -> dict[str, Any]: ...
    def correlations(self, threshold: float = 0.8) -> list[tuple[str, str, float]]: ...
    def report(self, min_correl: float = 0.8) -> str: ...
    def to_pandas(self) -> Any: ...
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
