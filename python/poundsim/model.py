"""Models built in Python: the model file's document (docs/input.md), table by table, with the
same keys and rules as the TOML the command line reads — one truth. Nothing here knows a key: the
C++ reader checks every table against its declared fields and names the key it refuses, exactly
as it does for a file.

    m = poundsim.Model(title="two frames")
    m.frame(name="A", mass=4e5, stiffness=np.full(10, 3e8), damping_ratio=0.05, storey_height=3.2)
    m.frame(name="B", storeys=6, mass=5e5, stiffness=5e8, damping_ratio=0.05, storey_height=3.2)
    m.gap_elements(gap=0.03, restitution=0.65)
    m.excitation(**poundsim.record(acceleration, dt=0.01, units="g", target_pga_g=0.4))
    m.analysis(kind="time_history", dt=0.002)
    th = poundsim.run(m)

The paper's dimensionless form: `m.dimensionless(storeys=[1, 1], eta=..., mu=..., ...)`.
"""

from __future__ import annotations

import copy
import os
from typing import Any, Optional, Sequence

import numpy as np

__all__ = ["Model", "harmonic", "record"]


def _max_storeys() -> int:
    """A frame's storeys at most: the reader's limit (docs/input.md)."""
    from . import _core

    return _core.max_storeys if _core is not None else 1000


def _input_error(message: str) -> Exception:
    """poundsim.InputError (imported here: the package imports this module first)."""
    from . import InputError

    return InputError(message)


def _plain(value: Any) -> Any:
    """NumPy arrays and scalars, tuples and paths as the TOML document's lists, numbers and text."""
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        for key in value:
            if not isinstance(key, str):
                raise _input_error(f"the key {key!r} is not a str: a model file's keys are text")
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return value


def harmonic(amplitude_g: float, *, ratio: Optional[float] = None, omega: Optional[float] = None,
             frequency_hz: Optional[float] = None) -> dict:
    """[excitation] of a harmonic ground acceleration A sin(ω̄t): A [g] and one of ratio ω̄/ω₁,
    omega ω̄ [rad/s] or frequency_hz."""
    keys = {"kind": "harmonic", "amplitude_g": amplitude_g, "ratio": ratio, "omega": omega,
            "frequency_hz": frequency_hz}
    return {k: v for k, v in keys.items() if v is not None}


def record(acceleration: Optional[Sequence[float]] = None, *, dt: Optional[float] = None,
           units: Optional[str] = None, file: Optional[str | os.PathLike] = None, **keys: Any) -> dict:
    """[excitation] of a ground-motion record: samples (`acceleration`, a NumPy array, every `dt`
    seconds, in `units` "g", "m/s2" or "cm/s2") or a file (AT2, COSMOS, columns: `file`, with
    `format`, `units`, `column`, `dt` as docs/records.md says); `scale` or `target_pga_g` scale it."""
    table: dict = {"kind": "record"}
    if acceleration is not None:
        table["acceleration"] = acceleration
    if file is not None:
        table["file"] = file
    if dt is not None:
        table["dt"] = dt
    if units is not None:
        table["units"] = units
    table.update(keys)
    return _plain(table)


class Model:
    """A model file built table by table (docs/input.md); `build()` reads and checks it."""

    def __init__(self, title: Optional[str] = None, document: Optional[dict] = None):
        if document is not None and not isinstance(document, dict):
            raise _input_error(f"Model(document=...): {type(document).__name__} is not a model file's document: "
                               "expected a dict of its tables, as Input.to_dict() or Model.to_dict() gives")
        if title is not None and not isinstance(title, str):
            raise _input_error(f"Model(title=...): {title!r} is not text (str)")
        self.document: dict = _plain(copy.deepcopy(document)) if document else {}
        if title is not None:
            self.document["title"] = title

    def _table(self, name: str, keys: dict) -> "Model":
        self.document.setdefault(name, {}).update(_plain(keys))
        return self

    def _append(self, path: Sequence[str], keys: dict) -> "Model":
        table = self.document
        for name in path[:-1]:
            table = table.setdefault(name, {})
        table.setdefault(path[-1], []).append(_plain(keys))
        return self

    def frame(self, **keys: Any) -> "Model":
        """One [[frames]] table, left to right: mass, stiffness (a value, or one per storey),
        storeys, damping, damping_ratio, storey_height, storey_law and its parameters, …"""
        # The storeys are bounded (as the reader says): a huge array is refused before it is copied.
        for key, value in keys.items():
            if isinstance(value, (np.ndarray, list, tuple)) and len(value) > _max_storeys():
                number = len(self.document.get("frames", [])) + 1
                raise _input_error(f"model: frames[{number}].{key}: has {len(value)} values: a frame has at most "
                                   f"{_max_storeys()} storeys")
        return self._append(["frames"], keys)

    def dimensionless(self, storeys: Sequence[int], storey_height: Optional[float] = None,
                      **parameters: Any) -> "Model":
        """[model] in the paper's dimensionless form: the storeys of the two frames and the
        paper's parameters (eta, mu, …, [model.dimensionless] of docs/input.md)."""
        model: dict = {"storeys": list(storeys), "dimensionless": parameters}
        if storey_height is not None:
            model["storey_height"] = storey_height
        return self._table("model", model)

    def gap_elements(self, **keys: Any) -> "Model":
        """[gap_elements]: law and its parameters, joint_width, pairing."""
        return self._table("gap_elements", keys)

    def gap_override(self, **keys: Any) -> "Model":
        """One [[gap_elements.override]]: frames, floor, and what changes."""
        return self._append(["gap_elements", "override"], keys)

    def gap_pair(self, **keys: Any) -> "Model":
        """One [[gap_elements.pair]] (pairing = "listed"): frames, floors or slab."""
        return self._append(["gap_elements", "pair"], keys)

    def excitation(self, **keys: Any) -> "Model":
        """[excitation]: `poundsim.harmonic(...)`, `poundsim.record(...)` or kind = "none"."""
        self.document["excitation"] = _plain(keys)
        return self

    def initial(self, displacement: Optional[Sequence[Sequence[float]]] = None,
                velocity: Optional[Sequence[Sequence[float]]] = None) -> "Model":
        """[initial]: per frame, the displacement [m] and velocity [m/s] of each floor."""
        keys = {k: v for k, v in (("displacement", displacement), ("velocity", velocity)) if v is not None}
        return self._table("initial", keys)

    def analysis(self, **keys: Any) -> "Model":
        """[analysis]: kind, integrator, dt, duration, output_dt, separation, …"""
        return self._table("analysis", keys)

    def output(self, channels: Sequence[str]) -> "Model":
        """[output] channels of a time history (patterns)."""
        return self._table("output", {"channels": list(channels)})

    def frf(self, **keys: Any) -> "Model":
        """[frf]: amplitude_g, ratios or ratio_min/ratio_max/points, sweep, …"""
        return self._table("frf", keys)

    def study(self, **keys: Any) -> "Model":
        """[study]: sampling, each, band, baseline, threads, …"""
        return self._table("study", keys)

    def study_parameter(self, **keys: Any) -> "Model":
        """One [[study.parameter]]: key, and values or min/max/points."""
        return self._append(["study", "parameter"], keys)

    def ensemble(self, **keys: Any) -> "Model":
        """[ensemble]: records (files) or folder and pattern, threads."""
        return self._table("ensemble", keys)

    def optimize(self, **keys: Any) -> "Model":
        """[optimize]: objective, each, band, algorithms, budgets, …"""
        return self._table("optimize", keys)

    def optimize_variable(self, **keys: Any) -> "Model":
        """One [[optimize.variable]]: key, min, max, start."""
        return self._append(["optimize", "variable"], keys)

    def to_dict(self) -> dict:
        """The document (a deep copy)."""
        return copy.deepcopy(self.document)

    def build(self, name: str = "model", base_dir: str | os.PathLike = ".", settings: Sequence[str] = ()):
        """Reads and checks the document as the command line reads a file (poundsim.from_dict):
        an Input, or InputError naming `name` and the key."""
        from . import from_dict

        return from_dict(self.document, name=name, base_dir=base_dir, settings=settings)

    def save(self, path: str | os.PathLike) -> None:
        """Writes the model file (TOML) the command line runs: `poundsim run PATH --out DIR`."""
        self.build(name=os.fspath(path)).save(path)

    def __repr__(self) -> str:
        return f"Model({', '.join(self.document)})"
