"""Type stubs of rtid's Python module (docstrings in rtid/__init__.py)."""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping, Sequence
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
def evaluate(experiment: Experiment | _Path, params: Params | None = None) -> dict[str, Any]: ...

class IdentifyResult:
    values: dict[str, float]
    initial: dict[str, float]
    standard_errors: dict[str, float]
    names: list[str]
    correlation: npt.NDArray[np.float64]
    intervals: dict[str, tuple[float | None, float | None]]
    interval_method: Literal["profile", "bootstrap", "standard errors"]
    profiles: dict[str, dict[str, Any]] | None
    resampling: dict[str, Any] | None
    warnings: list[dict[str, str]]
    interrupted: bool
    cost: float | None
    params: Params
    def to_dict(self) -> dict[str, Any]: ...

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
) -> SweepResult: ...
