"""Type stubs of poundsim._core, the C++ extension under the package poundsim (docs/python.md)."""

import os
from typing import Callable, Optional, Sequence

import numpy as np
import numpy.typing as npt

__version__: str

class InputError(ValueError):
    """Bad input: the command line's message, naming the file, the key and the rule."""

class SimulationError(RuntimeError):
    """The integration failed (naming the time and the element)."""

class Input:
    """A model file read and checked: the model, its excitation and its analysis."""

    @property
    def title(self) -> str: ...
    @property
    def source(self) -> os.PathLike[str]: ...
    @property
    def kind(self) -> str:
        """analysis.kind: "time_history", "frf", "study", "ensemble" or "optimize"."""
    @property
    def duration(self) -> float: ...
    @property
    def dt(self) -> float: ...
    @property
    def output_dt(self) -> float: ...
    @property
    def channels(self) -> list[str]:
        """[output] channels (empty: the default ones)."""
    @property
    def frame_count(self) -> int: ...
    @property
    def gap_count(self) -> int: ...
    def available_channels(self) -> list[tuple[str, str]]:
        """Every channel the model offers, as (name, unit), in the model's order."""
    def to_toml(self) -> str:
        """The input as TOML, as the command line's input.toml writes it."""
    def with_settings(self, settings: Sequence[str]) -> Input:
        """The same file read again with these `key=value` settings after its own."""
    def to_dict(self) -> dict:
        """The model file as written (settings applied, paths absolute) as dicts and lists."""
    def save(self, file: str | os.PathLike[str]) -> None:
        """Writes the model file as written (TOML), whole or not at all."""

def load(file: str | os.PathLike[str], settings: Sequence[str] = ...) -> Input:
    """Reads and checks a model file, with `key=value` settings applied as --set applies them."""

def loads(text: str, name: str = ..., base_dir: str | os.PathLike[str] = ..., settings: Sequence[str] = ...) -> Input:
    """Reads and checks a model given as TOML text."""

def from_dict(document: dict, name: str = ..., base_dir: str | os.PathLike[str] = ...,
              settings: Sequence[str] = ...) -> Input:
    """Reads and checks a model given as the model file's tables (dicts, lists, numbers, str, NumPy arrays)."""

class FrequencyResponseRun:
    table: dict[str, np.ndarray]
    units: dict[str, str]
    summary: dict

def run_frequency_response(input: Input, progress: Optional[Callable[[int, int], None]] = ...,
                           progress_interval: float = ...) -> FrequencyResponseRun: ...

class StudyRun:
    table: dict[str, np.ndarray]
    units: dict[str, str]
    summary: dict
    database: str
    spectra: Optional[tuple[dict[str, np.ndarray], dict[str, str]]]

def run_study(input: Input, out: str | os.PathLike[str], max_points: int = ...,
              progress: Optional[Callable[[int, int], None]] = ..., progress_interval: float = ...) -> StudyRun: ...

class OptimizationRun:
    summary: dict
    evaluations: dict[str, np.ndarray]
    evaluation_units: dict[str, str]
    optimum_frf: Optional[tuple[dict[str, np.ndarray], dict[str, str]]]
    bare_frf: Optional[tuple[dict[str, np.ndarray], dict[str, str]]]
    pareto: Optional[tuple[dict[str, np.ndarray], dict[str, str]]]

def run_optimization(input: Input, out: str | os.PathLike[str], progress: Optional[Callable[[int, int], None]] = ...,
                     progress_interval: float = ...) -> OptimizationRun: ...

class TimeHistoryRun:
    data: npt.NDArray[np.float64]
    channels: list[str]
    units: list[str]
    events: np.ndarray
    def summary(self) -> dict: ...

def run_time_history(
    input: Input,
    channels: Optional[Sequence[str]] = ...,
    progress: Optional[Callable[[float, float], None]] = ...,
    progress_interval: float = ...,
) -> TimeHistoryRun: ...

class TimeLeft:
    def __init__(self) -> None: ...
    def update(self, done: int, total: int, elapsed: float) -> Optional[float]: ...

def declared_unit(column: str) -> Optional[str]: ...
def input_schema() -> str: ...
def readable_duration(seconds: float) -> str: ...
