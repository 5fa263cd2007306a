"""poundsim's results as Python objects: what `poundsim.run` returns, and what `read` makes of a
folder the command line wrote (`poundsim run MODEL.toml --out DIR`). Pure Python and NumPy: it
imports without the C++ extension, so plots of the command line's outputs need no build.

- `Table`: named columns of one length (NumPy arrays), each with its unit; frf.csv, study.csv,
  ensemble.csv and evaluations.csv are tables, declared once in C++ (io/table.hpp) and handed to
  NumPy column by column.
- `Summary`: a summary (summary.json, optimize.json) as nested attributes, `.to_dict()`.
- `TimeHistory`, `FrequencyResponse`, `Study`, `Optimization`: one per kind of analysis.
"""

from __future__ import annotations

import csv
import json
import os
import re
from typing import Any, Iterable, Iterator, Mapping, Optional

import numpy as np

__all__ = ["Table", "Summary", "TimeHistory", "FrequencyResponse", "Study", "Optimization", "read",
           "channel_unit"]


class Table:
    """A results table: named columns of one length, each a NumPy array (float64 with NaN for a
    missing number, int64, or str), with its unit ("" for text, "1" for a ratio)."""

    def __init__(self, columns: Mapping[str, np.ndarray], units: Optional[Mapping[str, str]] = None):
        self._columns = {name: np.asarray(values) for name, values in columns.items()}
        lengths = {len(v) for v in self._columns.values()}
        if len(lengths) > 1:
            raise ValueError(f"the columns of a table have one length, not {sorted(lengths)}")
        self._units = {name: (units or {}).get(name, column_unit(name)) for name in self._columns}

    @property
    def names(self) -> list[str]:
        """The columns, in order."""
        return list(self._columns)

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self._columns[name]
        except KeyError:
            raise KeyError(f"no column {name!r} (the table has {', '.join(self._columns)})") from None

    def __contains__(self, name: str) -> bool:
        return name in self._columns

    def __iter__(self) -> Iterator[str]:
        return iter(self._columns)

    def __len__(self) -> int:
        """The number of rows."""
        return len(next(iter(self._columns.values()))) if self._columns else 0

    def unit(self, name: str) -> str:
        return self._units[name]

    @property
    def units(self) -> dict[str, str]:
        return dict(self._units)

    def to_records(self) -> np.ndarray:
        """The rows as one NumPy structured array (a copy)."""
        return np.rec.fromarrays(list(self._columns.values()), names=self.names)

    def to_pandas(self):
        """The table as a pandas DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self._columns)

    def to_dict(self) -> dict[str, list]:
        """Column name → its values as a list."""
        return {name: values.tolist() for name, values in self._columns.items()}

    @classmethod
    def from_records(cls, records: list[dict]) -> "Table":
        """A table of JSON-like records (a summary's list of floors, joints or elements): nested
        objects become dotted columns ("displacement_m.value", "rules.srss_m"), lists of values
        indexed ones ("frames[1]"); a value a record lacks is missing (NaN, or "")."""
        flat = [_flatten(r) for r in records]
        names: dict[str, None] = {}
        for row in flat:
            names.update(dict.fromkeys(row))
        return cls({name: _column([row.get(name) for row in flat]) for name in names})

    def __repr__(self) -> str:
        return f"Table({len(self)} rows: {', '.join(self._columns)})"

    @classmethod
    def read_csv(cls, path: str | os.PathLike) -> "Table":
        """A CSV table poundsim wrote: a column of whole numbers is int64, of numbers (an empty
        field is a missing one) float64, any other str."""
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        if not rows:
            raise ValueError(f"{path}: empty, not a poundsim table")
        header, body = rows[0], rows[1:]
        columns = {}
        for k, name in enumerate(header):
            columns[name] = _typed([r[k] for r in body])
        return cls(columns, csv_units(path, header))


def csv_units(path: str | os.PathLike, header: list[str]) -> Optional[dict[str, str]]:
    """The units of a CSV file's columns from the metadata poundsim writes beside it
    (``<file>-metadata.json``, W3C CSV on the Web: each column's ``titles`` and
    ``schema:unitText``), or None for a file without it (written by an older poundsim).

    Raises ValueError when the metadata does not declare the file's columns in order."""
    meta_path = os.fspath(path) + "-metadata.json"
    if not os.path.exists(meta_path):
        return None
    with open(meta_path) as f:
        declared = json.load(f)["tableSchema"]["columns"]
    titles = [c["titles"] for c in declared]
    if titles != list(header):
        raise ValueError(f"{meta_path}: declares the columns {titles}, the file has {list(header)}")
    return {c["titles"]: c["schema:unitText"] for c in declared}


def _typed(fields: list[str]) -> np.ndarray:
    if fields and all(f == "" for f in fields):
        return np.array(fields, dtype=str)  # nothing to tell: text, as an error column with no error
    if fields and all(re.fullmatch(r"-?\d+", f) for f in fields):
        return np.array([int(f) for f in fields], dtype=np.int64)
    try:
        return np.array([float(f) if f != "" else np.nan for f in fields], dtype=np.float64)
    except ValueError:
        return np.array(fields, dtype=str)


def _flatten(record: Any, prefix: str = "") -> dict:
    if isinstance(record, dict):
        out = {}
        for key, value in record.items():
            out.update(_flatten(value, f"{prefix}.{key}" if prefix else key))
        return out
    if isinstance(record, list):
        out = {}
        for k, value in enumerate(record, start=1):
            out.update(_flatten(value, f"{prefix}[{k}]"))
        return out
    return {prefix: record}


def _column(values: list) -> np.ndarray:
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present) and len(present) == len(values):
        return np.array(values, dtype=bool)
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present) and len(present) == len(values):
        return np.array(values, dtype=np.int64)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
        return np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    return np.array(["" if v is None else str(v) for v in values], dtype=str)


# The units of history channels and table columns, from their names (analysis/channels.hpp,
# docs/output.md); the module's own units are checked against these by python/tests.
_CHANNEL_UNITS = [
    (r"t", "s"), (r"u_\d+_\d+", "m"), (r"v_\d+_\d+", "m/s"), (r"a_(abs_)?\d+_\d+", "m/s2"),
    (r"V_\d+", "N"), (r"F_\d+(_\w+)?", "N"), (r"s_\d+(_\w+)?", "m"), (r"drift_ratio_\d+_\d+", "1"),
    (r"drift_\d+_\d+", "m"), (r"Fs_\d+_\d+", "N"), (r"E_\w+", "J"),
]


def channel_unit(name: str) -> str:
    """The unit of a history channel (or of time, "t") from its name."""
    for pattern, unit in _CHANNEL_UNITS:
        if re.fullmatch(pattern, name):
            return unit
    raise KeyError(f"{name!r} is not a poundsim channel")


# history.csv and events.csv name their columns with the unit as a suffix (channels.hpp's
# Channel::column); the module's channels and event fields are the bare names.
_UNIT_SUFFIXES = (("_m_s2", "m/s2"), ("_m_s", "m/s"), ("_m", "m"), ("_s", "s"), ("_N", "N"), ("_J", "J"))
_EVENT_FIELDS = {"t_s": "t", "relative_velocity_before_m_s": "relative_velocity_before",
                 "relative_velocity_after_m_s": "relative_velocity_after", "impulse_Ns": "impulse"}


def channel_of_column(column: str) -> tuple[str, str]:
    """The channel and its unit of a history.csv column: "a_abs_1_2_m_s2" → ("a_abs_1_2", "m/s2"),
    "t_s" → ("t", "s"), a ratio bare ("drift_ratio_1_1" → ("drift_ratio_1_1", "1"))."""
    for suffix, unit in _UNIT_SUFFIXES:
        if column.endswith(suffix):
            name = column[: -len(suffix)]
            try:
                if channel_unit(name) == unit:
                    return name, unit
            except KeyError:
                pass
    if channel_unit(column) == "1":
        return column, "1"
    raise KeyError(f"{column!r} is not a history.csv column")


def _channel_of(column: str, unit: str) -> tuple[str, str]:
    """The channel and its unit of a history.csv column whose unit its metadata declares: the name
    without the unit's suffix (Channel::column in channels.hpp appends it, "/" as "_")."""
    suffix = "" if unit in ("", "1") else "_" + unit.replace("/", "_")
    if not column.endswith(suffix):
        raise ValueError(f"history.csv: column {column!r} does not end in its unit's suffix {suffix!r}")
    return column[: len(column) - len(suffix)], unit


def column_unit(name: str) -> str:
    """The unit of a table column from its name: SI suffixes (_m, _s, _N, _J, _rad_s, _g), "1" for
    ratios (V1_W, max_ratio_to_free, gap_over_min_gap), "" otherwise; a summary's {value, time} pair flattened
    ("displacement_m.value", "displacement_m.time") has the value's unit and seconds."""
    name = re.sub(r"\[\d+\]$", "", name)
    if name.endswith(".time"):
        return "s"
    if name.endswith(".value"):
        name = name[: -len(".value")]
    if re.match(r"(amplification|rule_over_min_gap)\.", name):
        return "1"
    name = name.rsplit(".", 1)[-1]
    # A figure of merit's declared unit (analysis/figures_of_merit.hpp), when the extension is
    # there; else, and for other columns, the rules of io::column_unit (study_run.hpp).
    try:
        from . import _core
    except ImportError:
        _core = None
    if _core is not None and (declared := _core.declared_unit(name)) is not None:
        return declared
    for suffix, unit in (("_rad_s", "rad/s"), ("_m_s2", "m/s2"), ("_m_s", "m/s"), ("_m", "m"), ("_s", "s"),
                         ("_Ns", "N·s"), ("_N", "N"), ("_J", "J"), ("_g", "g"), ("_W", "1"), ("_at", "1")):
        if name.endswith(suffix):
            return unit
    if name.startswith("amp_"):
        return "1"
    return "1" if re.search(r"(^|_)(ratio|over|amplification)(_|$)", name) else ""


class Summary:
    """A summary (summary.json, optimize.json) as nested attributes (`summary.energy.input_J`);
    lists stay lists; `to_dict()` gives the plain dicts back."""

    def __init__(self, values: dict):
        self._values = values

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return _wrap(self._values[name])
        except KeyError:
            raise AttributeError(f"the summary has no {name!r} (it has {', '.join(self._values)})") from None

    def __getitem__(self, name: str) -> Any:
        return _wrap(self._values[name])

    def __contains__(self, name: str) -> bool:
        return name in self._values

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


class _WithSummary:
    _summary_source: Any

    @property
    def summary(self) -> Summary:
        """The run's summary (summary.json, or optimize.json) as attributes."""
        if not isinstance(self._summary_source, Summary):
            source = self._summary_source
            self._summary_source = Summary(source() if callable(source) else source)
        return self._summary_source

    @property
    def title(self) -> str:
        return self.summary.to_dict().get("title", "")


class TimeHistory(_WithSummary):
    """A time history: the recorded channels as one array (time × (1 + channels), of which every
    accessor is a view), the events as a structured array and the summary.

    Summary sections (summary.json, docs/output.md): `peaks`, `amplification`, `energy`,
    `separation` (the separation check: minimum gaps and the code rules per pair of floors),
    `gap_elements`, `events`."""

    def __init__(self, data: np.ndarray, channels: list[str], units: list[str], events: np.ndarray, summary: Any,
                 frame_names: Optional[list[str]] = None):
        self.data = data
        """rows × (1 + channels): time [s], then each channel."""
        self.channels = list(channels)
        self.units = list(units)
        self.events = events
        """One record per event: t, frame_left, frame_right, floor, right_floor, kind,
        relative_velocity_before, relative_velocity_after, impulse (events.csv's columns)."""
        self._summary_source = summary
        self._index = {name: k for k, name in enumerate(self.channels)}
        self._frame_names = frame_names

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

    # The summary's typed views (docs/output.md#summaryjson): one row per item, NumPy columns.
    @property
    def floor_peaks(self) -> Table:
        """Per floor of every frame: frame, floor, the peaks (displacement_m.value and .time,
        velocity, accelerations, interstorey drift and its ratio), the free frame's (free.…) and
        the amplifications pounding ÷ free (amplification.…)."""
        return Table.from_records(self.summary.to_dict()["peaks"]["floors"])

    @property
    def base_shear_peaks(self) -> Table:
        """Per frame: value_N, time, over_own_weight, over_frame1_weight, free_value_N, amplification."""
        return Table.from_records(self.summary.to_dict()["peaks"]["base_shear"])

    @property
    def separation(self) -> Table:
        """The separation check, per pair of facing floors: min_gap_m (the smallest gap that avoids
        contact, from the free frames) and when, the free peaks, the code rules (rules.absolute_sum_m,
        rules.srss_m, rules.srss_same_floor_levels_m, rules.ddc_m) and each ÷ the minimum gap, the
        element's gap_m and whether there was contact."""
        return Table.from_records(self.summary.to_dict()["separation"])

    @property
    def gap_element_results(self) -> Table:
        """Per gap element: contacts, impacts, peak force, impulse and shortening, contact time,
        effective restitution, dissipated energy, min_gap_m (summary.json's gap_elements)."""
        return Table.from_records(self.summary.to_dict()["gap_elements"])

    @property
    def energy(self) -> Summary:
        """The energy balance at the end [J]: input_J, kinetic_J, storey and gap strain, damping,
        impact_loss_J, residual_J and the relative residual."""
        return self.summary.energy

    @property
    def frame_names(self) -> list[str]:
        """The frames' names ("frame 1", … where the input gives none)."""
        if self._frame_names is None:
            summary = self.summary.to_dict()
            frames = summary.get("model", {}).get("frames") or summary.get("frames", [])
            self._frame_names = [f.get("name") or f"frame {k + 1}" for k, f in enumerate(frames)]
        return self._frame_names

    def to_pandas(self):
        """The history as a pandas DataFrame indexed by time (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.values, index=pd.Index(self.time, name="t"), columns=self.channels)

    def __repr__(self) -> str:
        return f"TimeHistory({self.data.shape[0]} instants × {len(self.channels)} channels, {len(self.events)} events)"


class FrequencyResponse(_WithSummary):
    """A frequency response: frf.csv's table (one row per point: ratio ω̄/ω₁, V<f>_W, V<f>_free_W,
    periodicity, branch, …, docs/output.md) and the summary (the peaks per branch and frame)."""

    def __init__(self, table: Table, summary: Any):
        self.table = table
        self._summary_source = summary

    def __getitem__(self, column: str) -> np.ndarray:
        return self.table[column]

    @property
    def frames(self) -> int:
        return sum(1 for n in self.table.names if re.fullmatch(r"V\d+_W", n))

    def __repr__(self) -> str:
        return f"FrequencyResponse({len(self.table)} points, {self.frames} frames)"


class Continuation(_WithSummary):
    """A continuation in a model parameter: orbits.csv's table (one row per continued orbit:
    parameter, ratio, V<f>_W, …, branch_id, stable, multipliers, docs/output.md) and the summary
    (the parameter's key and range, the branches and the bifurcations)."""

    def __init__(self, table: Table, summary: Any):
        self.table = table
        self._summary_source = summary

    def __getitem__(self, column: str) -> np.ndarray:
        return self.table[column]

    def __repr__(self) -> str:
        return f"Continuation({len(self.table)} orbits in {self.summary.to_dict().get('parameter', {}).get('key', '?')})"


class Study(_WithSummary):
    """A study or an ensemble: its table (study.csv or ensemble.csv: id, status, the parameters,
    the figures of merit, run_time_s, error), its summary and the database it is kept in."""

    def __init__(self, table: Table, summary: Any, database: Optional[str] = None, spectra: Optional[Table] = None):
        self.table = table
        self._summary_source = summary
        self.database = database
        """The SQLite database (study.sqlite, ensemble.sqlite), when it was kept."""
        self.spectra = spectra
        """An ensemble with [ensemble.scaling]: spectra.csv (period_s, target_g, mean_g, sa_<i>_g of record i
        scaled), else None."""

    def __getitem__(self, column: str) -> np.ndarray:
        return self.table[column]

    @property
    def kind(self) -> str:
        return self.summary.to_dict()["analysis"]["kind"]

    @property
    def parameters(self) -> list[str]:
        """The keys varied (for an ensemble: the record file)."""
        return list(self.summary.to_dict().get("parameters", []))

    @property
    def complete(self) -> bool:
        return bool(self.summary.to_dict()["complete"])

    def __repr__(self) -> str:
        return f"Study({self.kind}, {len(self.table)} points)"


class Optimization(_WithSummary):
    """An optimisation: optimize.json (the optimum, its figures against bare pounding, the stages,
    the constraints), every evaluation (evaluations.csv), for a frequency-response objective the
    optimum's and bare pounding's responses (optimum_frf.csv, bare_frf.csv), and with
    [optimize.pareto] the front (pareto.csv)."""

    def __init__(self, summary: Any, evaluations: Table, optimum_frf: Optional[Table] = None,
                 bare_frf: Optional[Table] = None, pareto: Optional[Table] = None):
        self._summary_source = summary
        self.evaluations = evaluations
        self.optimum_frf = optimum_frf
        self.bare_frf = bare_frf
        self.pareto = pareto

    @property
    def optimum(self) -> dict[str, float]:
        """Design variable key → its value at the optimum."""
        return dict(self.summary.to_dict()["optimum"])

    def __repr__(self) -> str:
        return f"Optimization({len(self.evaluations)} evaluations, optimum {self.optimum})"


def read(folder: str | os.PathLike):
    """The results the command line wrote into `folder`: a TimeHistory (history.csv), a
    FrequencyResponse (frf.csv), a Continuation (orbits.csv), a Study (study.csv or ensemble.csv) or an Optimization
    (optimize.json)."""
    folder = os.fspath(folder)

    def path(name: str) -> str:
        return os.path.join(folder, name)

    def summary(name: str = "summary.json") -> dict:
        with open(path(name)) as f:
            return json.load(f)

    if os.path.exists(path("optimize.json")):
        frf = {n: Table.read_csv(path(f"{n}.csv")) if os.path.exists(path(f"{n}.csv")) else None
               for n in ("optimum_frf", "bare_frf", "pareto")}
        return Optimization(summary("optimize.json"), Table.read_csv(path("evaluations.csv")), **frf)
    if os.path.exists(path("history.csv")):
        with open(path("history.csv"), newline="") as f:
            header = next(csv.reader(f))
        data = np.loadtxt(path("history.csv"), delimiter=",", skiprows=1, ndmin=2)
        units = csv_units(path("history.csv"), header)
        channels = [channel_of_column(c) if units is None else _channel_of(c, units[c]) for c in header[1:]]
        events = Table.read_csv(path("events.csv")) if os.path.exists(path("events.csv")) else None
        records = _no_events()
        if events is not None and len(events):
            records = events.to_records()
            records.dtype.names = tuple(_EVENT_FIELDS.get(n, n) for n in records.dtype.names)
        return TimeHistory(data, [c for c, _ in channels], [u for _, u in channels], records, summary())
    if os.path.exists(path("frf.csv")):
        return FrequencyResponse(Table.read_csv(path("frf.csv")), summary())
    if os.path.exists(path("orbits.csv")):
        return Continuation(Table.read_csv(path("orbits.csv")), summary())
    for stem in ("study", "ensemble"):
        if os.path.exists(path(f"{stem}.csv")):
            db = path(f"{stem}.sqlite")
            spectra = Table.read_csv(path("spectra.csv")) if os.path.exists(path("spectra.csv")) else None
            return Study(Table.read_csv(path(f"{stem}.csv")), summary(), db if os.path.exists(db) else None, spectra)
    raise ValueError(f"{folder}: no poundsim results (history.csv, frf.csv, orbits.csv, study.csv, ensemble.csv or "
                     "optimize.json)")


def _no_events() -> np.ndarray:
    return np.zeros(0, dtype=[("t", "<f8"), ("frame_left", "<i4"), ("frame_right", "<i4"), ("floor", "<i4"),
                              ("right_floor", "<i4"), ("kind", "<U10"), ("relative_velocity_before", "<f8"),
                              ("relative_velocity_after", "<f8"), ("impulse", "<f8")])
