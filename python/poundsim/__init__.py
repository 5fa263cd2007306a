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

    frf = poundsim.run(poundsim.load("examples/paper/fig2c.toml"))   # any kind of analysis
    frf["ratio"], frf["V1_W"]

    model = poundsim.Model(title="two frames")          # or built in Python
    model.frame(mass=4e5, stiffness=[3e8] * 10, damping_ratio=0.05, storey_height=3.2)

Inputs are the command line's TOML (`load`, `loads`, `Model`, `Input.to_toml`, `Input.save`): one
truth. Bad input or a bad argument raises poundsim.InputError (a ValueError and a TypeError) with
the command line's message, naming the file, the key or the argument and the rule; a failed integration raises poundsim.SimulationError (a
RuntimeError). Runs release the GIL; Ctrl-C stops them and raises KeyboardInterrupt.

`poundsim.results` and `poundsim.plot` import without the C++ extension: `poundsim.read(DIR)`
reads what the command line wrote, and the plots draw either.
"""

from __future__ import annotations

import math
import os
import pkgutil
import sys
import tempfile
import time
from typing import Any, Callable, Optional, Sequence

import numpy as np

# A package imported from a source tree (python/ beside the plotting scripts) finds the extension
# where it is installed: every poundsim folder on sys.path is part of the package.
__path__ = pkgutil.extend_path(__path__, __name__)

from .results import Continuation, FrequencyResponse, Optimization, Study, Summary, Table, TimeHistory, read  # noqa: E402
from .model import Model, harmonic, record  # noqa: E402

try:
    from . import _core
    from ._core import Input, InputError, SimulationError, __version__  # noqa: F401
except ImportError as missing:  # the results and plots still work
    _core = None
    _missing = missing
    __version__ = "unknown"

    class InputError(ValueError, TypeError):  # type: ignore[no-redef]
        """Bad input (the C++ extension raises its own; this one stands in when it is missing)."""

    class SimulationError(RuntimeError):  # type: ignore[no-redef]
        """The integration failed."""

__all__ = ["Continuation", "FrequencyResponse", "Input", "InputError", "Model", "Optimization", "SimulationError", "Study",
           "Summary", "Table", "TimeHistory", "__version__", "from_dict", "harmonic", "input_schema", "load", "loads",
           "read", "record", "run", "stiffness_check"]


def _extension():
    if _core is None:
        raise ImportError(f"poundsim's C++ extension (poundsim._core) is not built or installed: {_missing}; "
                          "build it (cmake --build --preset release) and install it (cmake --install "
                          "build/release --prefix ~/.local), or set PYTHONPATH=BUILD/python") from _missing
    return _core


def load(file: str | os.PathLike, settings: Sequence[str] = ()) -> "Input":
    """Reads and checks a model file, with `key=value` settings applied as --set applies them."""
    return _extension().load(file, list(settings))


def loads(text: str, name: str = "model.toml", base_dir: str | os.PathLike = ".",
          settings: Sequence[str] = ()) -> "Input":
    """Reads and checks a model given as TOML text; `name` names it in messages, relative record
    paths start from `base_dir`."""
    return _extension().loads(text, name, base_dir, list(settings))


def from_dict(document: dict, name: str = "model", base_dir: str | os.PathLike = ".",
              settings: Sequence[str] = ()) -> "Input":
    """Reads and checks a model given as the TOML document's tables (dicts, lists, numbers, str;
    NumPy arrays as lists): the keys and rules of docs/input.md, the same messages, with `name`
    in place of the file. `Input.to_dict()` gives such a document back."""
    return _extension().from_dict(document, name, base_dir, list(settings))


def input_schema() -> dict:
    """The JSON Schema (draft 7) of a model file, as a dict: every key of every table with its type,
    range or names, default, unit and meaning (what `poundsim schema` writes). A document that
    from_dict accepts is valid against it; the rules between keys stay the reader's."""
    import json
    return json.loads(_extension().input_schema())


def _console_progress(unit: str, clock: Callable[[], float] = time.monotonic) -> Callable[[float, float], None]:
    """A one-line progress bar on stderr, with the time taken and, once there is a rate, the time
    left (the C++ TimeLeft of the command line's bar: points done since the run began)."""
    core = _extension()
    start = clock()
    left = core.TimeLeft()

    def show(done: float, total: float) -> None:
        fraction = 1.0 if total <= 0 else min(1.0, done / total)
        bar = "#" * int(30 * fraction)
        where = f"t = {done:.3f} s" if unit == "s" else f"{int(done)}/{int(total)} {unit}"
        elapsed = clock() - start
        # A time history reports simulated seconds: its rate is of them, as the items of the others.
        estimate = left.update(int(round(done * 1000)), int(round(total * 1000)), elapsed) if unit == "s" \
            else left.update(int(done), int(total), elapsed)
        timing = core.readable_duration(elapsed) + (f" — {core.readable_duration(estimate)} left" if estimate else "")
        sys.stderr.write(f"\rpoundsim [{bar:<30}] {100 * fraction:5.1f} %  {where}, {timing:<24}")
        if fraction >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return show


def run(
    input: "Input | Model",
    channels: Optional[Sequence[str]] = None,
    out: Optional[str | os.PathLike] = None,
    max_points: Optional[int] = None,
    progress: Optional[Callable[[float, float], None]] | bool = None,
    progress_interval: float = 0.1,
):
    """Runs an input (or a Model) and returns its results, by its analysis.kind:

    - "time_history": a TimeHistory (channels: patterns of the channels to record, `["u_*_8",
      "drift_ratio_*"]`; default: the input's [output] channels, or history.csv's);
    - "frf": a FrequencyResponse;
    - "study", "ensemble": a Study; its database (study.sqlite, ensemble.sqlite) is kept in `out`
      (a run stopped there goes on from where it stopped when run again; `max_points` runs at
      most that many new points), or in a temporary folder removed afterwards;
    - "optimize": an Optimization (files in `out` when given, as the command line writes them).

    progress: a callable progress(done, total) — the time reached and the duration [s] of a
        time history, the points (records, evaluations) done and to do of the others — True for a
        progress bar on stderr, False for none; by default a bar when stderr is a terminal. It is
        called at most every `progress_interval` seconds of wall time (0: at every output instant
        of a time history; the other analyses are looked at every 10 ms at most), and at the end.
    Ctrl-C stops the run and raises KeyboardInterrupt; a study's database stays whole.
    """
    core = _extension()
    if isinstance(input, Model):
        input = input.build()
    if not isinstance(input, core.Input):
        raise InputError(f"poundsim.run takes an Input (poundsim.load, loads, from_dict) or a Model, "
                         f"not {type(input).__name__}")
    if isinstance(progress_interval, bool) or not (isinstance(progress_interval, (int, float))
                                                   and math.isfinite(progress_interval) and progress_interval >= 0):
        raise InputError(f"progress_interval: {progress_interval!r} s must be a finite number ≥ 0")
    kind = input.kind
    if progress is None:
        progress = sys.stderr.isatty()
    if progress is True:
        progress = _console_progress({"time_history": "s", "optimize": "evaluations",
                                      "ensemble": "records"}.get(kind, "points"))
    elif progress is False:
        progress = None
    elif not callable(progress):
        raise InputError(f"progress: {progress!r} is neither True, False, None nor a callable progress(done, total)")
    if channels is not None:
        if kind != "time_history":
            raise InputError(f"{input.source}: channels are for time histories, not analysis.kind = {kind!r}")
        if isinstance(channels, str) or not all(isinstance(c, str) for c in _iterable(channels, "channels")):
            raise InputError(f"channels: {channels!r}: expected a list of channel patterns (str), "
                             f"e.g. [\"u_1_*\", \"drift_ratio_*\"]")
    if max_points is not None:
        if kind not in ("study", "ensemble"):
            raise InputError(f"max_points is for studies and ensembles, not analysis.kind = {kind!r}")
        if isinstance(max_points, bool) or not isinstance(max_points, int) or max_points < 1:
            raise InputError(f"max_points: {max_points!r}: expected a whole number of points from 1")
    if out is not None:
        if kind in ("time_history", "frf", "continuation"):
            raise InputError(f"out is for studies, ensembles and optimisations (their databases and files), not "
                             f"analysis.kind = {kind!r}: save the arrays, or run the command line for its files")
        if not isinstance(out, (str, os.PathLike)):
            raise InputError(f"out: {out!r}: expected a folder (str or path)")
    if kind == "time_history":
        r = core.run_time_history(input, None if channels is None else list(channels), progress, progress_interval)
        return TimeHistory(r.data, r.channels, r.units, r.events, r.summary)
    if kind == "frf":
        r = core.run_frequency_response(input, progress, progress_interval)
        return FrequencyResponse(Table(r.table, r.units), r.summary)
    if kind == "continuation":
        r = core.run_continuation(input)
        return Continuation(Table(r.table, r.units), r.summary)
    with tempfile.TemporaryDirectory(prefix="poundsim_") as scratch:
        folder = os.fspath(out) if out is not None else scratch
        if kind in ("study", "ensemble"):
            r = core.run_study(input, folder, max_points or 0, progress, progress_interval)
            summary = r.summary
            if out is None:
                summary["database"] = None  # it was in the temporary folder, now removed
            spectra = Table(*r.spectra) if r.spectra is not None else None
            return Study(Table(r.table, r.units), summary, r.database if out is not None else None, spectra)
        if kind == "optimize":
            r = core.run_optimization(input, folder, progress, progress_interval)
            frf = {name: Table(*getattr(r, name)) if getattr(r, name) is not None else None
                   for name in ("optimum_frf", "bare_frf", "pareto")}
            return Optimization(r.summary, Table(r.evaluations, r.evaluation_units), **frf)
    raise InputError(f"{input.source}: analysis.kind = {kind!r} cannot be run")


def stiffness_check(input: "Input | Model", factor: float = 2.0) -> "Table":
    """How much a time history's peaks move when every gap element's contact stiffness is
    multiplied by `factor` (2: doubled). The stiffness is [gap_elements] stiffness (and every
    override's), or η of the dimensionless form; the run is the input's own, then the same with
    the stiffer contacts. Returns a Table with a row per peak — quantity ("contact_force_N", and
    per frame and floor "displacement_m", "interstorey_drift_m", "absolute_acceleration_m_s2"),
    frame, floor (0 for the contact force), at_k, at_factor_k and change = at_factor_k / at_k − 1.
    A conclusion that moves with k by more than the tolerance it needs is decided by k
    (docs/model.md, "Choosing the contact stiffness")."""
    core = _extension()
    if isinstance(input, Model):
        input = input.build()
    if not isinstance(input, core.Input):
        raise InputError(f"stiffness_check takes an Input or a Model, not {type(input).__name__}")
    if input.kind != "time_history":
        raise InputError(f"{input.source}: stiffness_check runs time histories, not analysis.kind = {input.kind!r}")
    if isinstance(factor, bool) or not (isinstance(factor, (int, float)) and math.isfinite(factor) and factor > 0):
        raise InputError(f"factor: {factor!r} must be a finite number > 0")
    stiffer = input.to_dict()
    dimensionless = stiffer.get("model", {}).get("dimensionless")
    if dimensionless is not None:
        scaled = ["model.dimensionless.eta"]
        dimensionless["eta"] = dimensionless.get("eta", 0.0) * factor
    else:
        gaps = stiffer.get("gap_elements", {})
        tables = [gaps] + list(gaps.get("override", []))
        scaled = [t for t in tables if "stiffness" in t]
        for t in scaled:
            t["stiffness"] = t["stiffness"] * factor
    if not scaled:
        raise InputError(f"{input.source}: the gap elements' law has no stiffness to vary (gap_elements.stiffness)")
    runs = [run(input, progress=False), run(from_dict(stiffer, name=f"{input.source} (k × {factor:g})"), progress=False)]
    rows: dict = {"quantity": [], "frame": [], "floor": [], "at_k": [], "at_factor_k": []}

    def add(quantity: str, frame: int, floor: int, values: list) -> None:
        for column, value in zip(("quantity", "frame", "floor", "at_k", "at_factor_k"),
                                 (quantity, frame, floor, *values)):
            rows[column].append(value)

    forces = [r.summary.to_dict()["max_gap_force_N"] for r in runs]
    add("contact_force_N", 0, 0, forces)
    floors = [r.summary.to_dict()["peaks"]["floors"] for r in runs]
    for a, b in zip(*floors):
        for quantity in ("displacement_m", "interstorey_drift_m", "absolute_acceleration_m_s2"):
            add(quantity, a["frame"], a["floor"], [a[quantity]["value"], b[quantity]["value"]])
    at_k, at_factor_k = np.asarray(rows["at_k"], float), np.asarray(rows["at_factor_k"], float)
    with np.errstate(divide="ignore", invalid="ignore"):
        change = np.where(at_k != 0, at_factor_k / at_k - 1.0, np.nan)
    return Table({"quantity": np.asarray(rows["quantity"]), "frame": np.asarray(rows["frame"], np.int64),
                  "floor": np.asarray(rows["floor"], np.int64), "at_k": at_k, "at_factor_k": at_factor_k,
                  "change": change},
                 {"quantity": "", "frame": "", "floor": "", "at_k": "SI", "at_factor_k": "SI", "change": "1"})


def _iterable(value: Any, name: str) -> list:
    """`value` as a list, or InputError naming the argument when it is not a sequence."""
    try:
        return list(value)
    except TypeError:
        raise InputError(f"{name}: {value!r}: expected a list") from None
