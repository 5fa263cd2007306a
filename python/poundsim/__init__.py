"""poundsim for Python: seismic pounding of adjacent buildings and its control by gap elements.

The C++ library (poundsim._core) does the work; this package gives it the shape a Python user
expects (docs/python.md)::

    import poundsim
    model = poundsim.load("examples/three_buildings_el_centro.toml")
    th = poundsim.run(model, channels=["u_*", "drift_ratio_*", "F_*"])
    th["u_1_8"]                 # a NumPy view of one channel [m]
    th.time, th.values          # views of the history: time × channel, no copy
    th.summary.energy.input_J   # summary.json as attributes
    th.to_pandas()              # a DataFrame indexed by time (pandas, when installed)

Inputs are the command line's TOML files (`load`, `loads`, `Input.to_toml`): one truth. Bad input
raises ValueError (poundsim.InputError) with the command line's message, naming the file, the key
and the rule; a failed integration raises poundsim.SimulationError (a RuntimeError). Runs release
the GIL; Ctrl-C stops them and raises KeyboardInterrupt.
"""

from __future__ import annotations

import sys
from typing import Any, Callable, Iterable, Optional, Sequence

import numpy as np

from ._core import Input, InputError, SimulationError, __version__, load, loads
from . import _core

__all__ = ["Input", "InputError", "SimulationError", "Summary", "TimeHistory", "__version__", "load", "loads", "run"]


class Summary:
    """summary.json as nested attributes (`summary.energy.input_J`), lists kept as lists;
    `to_dict()` gives the plain dicts back."""

    def __init__(self, values: dict):
        self._values = values

    def __getattr__(self, name: str) -> Any:
        try:
            return _wrap(self._values[name])
        except KeyError:
            raise AttributeError(f"the summary has no {name!r} (it has {', '.join(self._values)})") from None

    def __getitem__(self, name: str) -> Any:
        return _wrap(self._values[name])

    def __dir__(self) -> Iterable[str]:
        return list(self._values)

    def __repr__(self) -> str:
        return f"Summary({', '.join(self._values)})"

    def to_dict(self) -> dict:
        return self._values


def _wrap(value: Any) -> Any:
    if isinstance(value, dict):
        return Summary(value)
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


class TimeHistory:
    """A time history's results: the recorded channels as NumPy arrays (views of one buffer the
    run filled, no copy), the events as a structured array, the summary."""

    def __init__(self, run: "_core.TimeHistoryRun"):
        self._run = run
        self.data: np.ndarray = run.data
        """rows × (1 + channels): time [s], then each channel."""
        self.channels: list[str] = list(run.channels)
        self.units: list[str] = list(run.units)
        self.events: np.ndarray = run.events
        """One record per event: t, frame_left, frame_right, floor, right_floor, kind,
        relative_velocity_before, relative_velocity_after, impulse (events.csv's columns)."""
        self._index = {name: k for k, name in enumerate(self.channels)}
        self._summary: Optional[Summary] = None

    @property
    def time(self) -> np.ndarray:
        """The output instants [s] (a view)."""
        return self.data[:, 0]

    @property
    def values(self) -> np.ndarray:
        """time × channel (a view), in the order of `channels`."""
        return self.data[:, 1:]

    def __getitem__(self, channel: str) -> np.ndarray:
        """One channel's history (a view)."""
        try:
            return self.data[:, 1 + self._index[channel]]
        except KeyError:
            raise KeyError(f"no channel {channel!r} was recorded (choose it with channels=[...])") from None

    def __contains__(self, channel: str) -> bool:
        return channel in self._index

    def unit(self, channel: str) -> str:
        return self.units[self._index[channel]]

    @property
    def summary(self) -> Summary:
        """summary.json's content (peaks, amplifications, energy, separation rules)."""
        if self._summary is None:
            self._summary = Summary(self._run.summary())
        return self._summary

    def to_pandas(self):
        """The history as a pandas DataFrame indexed by time (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.values, index=pd.Index(self.time, name="t"), columns=self.channels)

    def __repr__(self) -> str:
        return f"TimeHistory({self.data.shape[0]} instants × {len(self.channels)} channels, {len(self.events)} events)"


def _console_progress() -> Callable[[float, float], None]:
    """A one-line progress bar on stderr."""

    def show(t: float, duration: float) -> None:
        done = 1.0 if duration <= 0 else min(1.0, t / duration)
        bar = "#" * int(30 * done)
        sys.stderr.write(f"\rpoundsim [{bar:<30}] {100 * done:5.1f} %  t = {t:.3f} s")
        if done >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return show


def run(
    input: Input,
    channels: Optional[Sequence[str]] = None,
    progress: Optional[Callable[[float, float], None]] | bool = None,
    progress_interval: float = 0.1,
) -> TimeHistory:
    """Runs an input and returns its results.

    channels: patterns of the channels to record (`["u_*_8", "drift_ratio_*"]`, docs/input.md
        [output]); default: the input's [output] channels, or history.csv's default ones.
    progress: a callable progress(t, duration), True for a progress bar on stderr, False for
        none; by default a bar when stderr is a terminal. It is called at most every
        `progress_interval` seconds of wall time (0: at every output instant), and at the end.
    """
    if progress is None:
        progress = sys.stderr.isatty()
    if progress is True:
        progress = _console_progress()
    elif progress is False:
        progress = None
    if input.kind != "time_history":
        raise ValueError(f"{input.source}: analysis.kind: {input.kind!r}: poundsim.run runs time histories")
    return TimeHistory(
        _core.run_time_history(input, None if channels is None else list(channels), progress, progress_interval))
