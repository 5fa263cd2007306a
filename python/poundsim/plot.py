"""Matplotlib figures of poundsim's results, in engineering units, sized for a journal.

Each function draws one kind of result of `poundsim.results` (what `poundsim.run` returns, or
`poundsim.read(DIR)` makes of a folder the command line wrote) and returns the matplotlib Figure;
none calls `plt.show`. A function that draws one axes takes `ax=` to draw into a user's axes;
without it the function makes a new figure, `size="column"` (a journal's single column, 3.5 in
wide), `"page"` (double column, 7.2 in) or a (width, height) tuple in inches, under
`journal_style()` (8 pt fonts, thin lines) and at `DPI` (300) dots per inch, so that
`fig.savefig("fig.png")` writes print resolution.

    import poundsim, poundsim.plot as pp
    th = poundsim.read("results/el_centro")
    pp.time_history(th, ["u_*_8", "u_2_4"]).savefig("roofs.png")
    pp.envelopes(th, size="page").savefig("envelopes.pdf")

Units (the histories are SI; `to_engineering` converts):

| quantity | channels | drawn in |
|---|---|---|
| displacement, drift, gap shortening | `u_`, `drift_`, `s_` [m] | mm |
| velocity | `v_` [m/s] | m/s (floor velocities are 0.01–2 m/s: readable as they are) |
| acceleration | `a_`, `a_abs_` [m/s²] | g = 9.81 m/s² (poundsim's `standard_gravity`, units.hpp) |
| drift ratio | `drift_ratio_` [1] | % |
| force | `V_`, `F_`, `Fs_` [N] | kN; MN when the peak exceeds 10 MN; N when it is below 1 kN |
| energy | `E_` [J] | kJ; MJ above 10 MJ; J below 1 kJ |

Frames are named as the model names them (summary.json's `model.frames[].name`; a bare number
reads "frame 3"), else "frame 1", "frame 2", …

This module needs NumPy and Matplotlib only: it imports without poundsim's C++ extension.
"""

from __future__ import annotations

import contextlib
import fnmatch
import os
import re
import textwrap
from typing import Any, Iterator, Optional, Sequence, Union

import matplotlib
import numpy as np
from matplotlib.ticker import FuncFormatter

from .results import Continuation, FrequencyResponse, Optimization, Study, Table, TimeHistory, column_unit

__all__ = ["COLUMN_WIDTH", "PAGE_WIDTH", "SIZES", "DPI", "STANDARD_GRAVITY", "JOURNAL_RC", "COLOURS", "colour",
           "journal_style", "to_engineering", "frame_names", "channel_label", "parameter_label", "metric_label",
           "time_history", "gap_forces", "hysteresis", "gap_hysteresis", "envelopes", "energy", "frf", "study_map",
           "ensemble_amplification", "ensemble_floor_amplification", "optimization", "pareto", "compare_runs"]

COLUMN_WIDTH = 3.5
"""A journal's single column [in]."""
PAGE_WIDTH = 7.2
"""A journal's double column (the page) [in]."""
SIZES = {"column": (COLUMN_WIDTH, 2.6), "page": (PAGE_WIDTH, 3.4)}
"""The figure sizes `size=` names, (width, height) [in]; a function drawing several axes makes
its figure taller."""
DPI = 300
"""Dots per inch of the figures the functions make (what `savefig` writes; journal_style's
savefig.dpi). Lower it (`poundsim.plot.DPI = 100`) for smaller figures on a screen."""
STANDARD_GRAVITY = 9.81
"""g [m/s²], poundsim's (include/poundsim/units.hpp, the paper's value): accelerations in g."""

JOURNAL_RC = {
    "font.size": 8, "axes.titlesize": 8, "axes.labelsize": 8, "xtick.labelsize": 7, "ytick.labelsize": 7,
    "legend.fontsize": 6.5, "legend.frameon": False, "legend.handlelength": 2.2,
    "lines.linewidth": 0.8, "lines.markersize": 3.0, "patch.linewidth": 0.5,
    "axes.linewidth": 0.6, "grid.linewidth": 0.4, "grid.alpha": 0.35,
    "xtick.major.width": 0.6, "ytick.major.width": 0.6, "xtick.major.size": 2.5, "ytick.major.size": 2.5,
    "xtick.direction": "in", "ytick.direction": "in",
    "savefig.dpi": DPI, "pdf.fonttype": 42, "ps.fonttype": 42,
}
"""The rcParams of `journal_style()`."""

# Frame 1 blue, frame 2 red (the paper's figures), then the rest.
COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:pink", "tab:olive",
           "tab:cyan", "tab:grey"]

SizeArg = Union[str, Sequence[float]]


def colour(i: int) -> str:
    """The colour of the i-th curve or frame (0-based), cycling."""
    return COLOURS[i % len(COLOURS)]


@contextlib.contextmanager
def journal_style(**overrides: Any) -> Iterator[None]:
    """rcParams for a journal figure, for the duration of a `with` block: 8 pt text (7 pt ticks,
    6.5 pt legends), thin lines, 300 dpi when saved, TrueType fonts in PDF. The plot functions
    draw their new figures under it; draw your own figure inside the block to match them."""
    with matplotlib.rc_context({**JOURNAL_RC, "savefig.dpi": DPI, **overrides}):
        yield


# --- Units -----------------------------------------------------------------------------------

def _scale(unit: str, peak: float) -> tuple[float, str]:
    """(factor, label): a value in `unit` times factor is in the unit `label`, chosen by the peak
    magnitude where the unit depends on it (N, J)."""
    if unit == "m":
        return 1e3, "mm"
    if unit == "m/s2":
        return 1.0 / STANDARD_GRAVITY, "g"
    if unit == "1":
        return 100.0, "%"
    if unit in ("N", "J"):
        big, small = ("MN", "kN") if unit == "N" else ("MJ", "kJ")
        if peak > 1e7:
            return 1e-6, big
        if peak >= 1e3:
            return 1e-3, small
        return 1.0, unit
    return 1.0, unit


def to_engineering(unit: str, values: Any, peak: Optional[float] = None) -> tuple[np.ndarray, str]:
    """Values in SI `unit` ("m", "m/s", "m/s2", "1", "N", "J", "s") as drawn, and their unit: m →
    mm, m/s² → g, ratio → %, N → kN (MN above 10 MN, N below 1 kN), J → kJ (MJ above 10 MJ, J below
    1 kJ); m/s and s stay. `peak` chooses among kN, MN… (default: the values' own peak)."""
    v = np.asarray(values, dtype=float)
    if peak is None:
        finite = np.abs(v[np.isfinite(v)])
        peak = float(finite.max()) if finite.size else 0.0
    factor, label = _scale(unit, peak)
    return v * factor, label


def _peak(arrays: Sequence[np.ndarray]) -> float:
    peaks = [float(np.nanmax(np.abs(a))) for a in arrays if np.size(a) and np.isfinite(a).any()]
    return max(peaks, default=0.0)


# --- Names -----------------------------------------------------------------------------------

def _summary_dict(result: Any) -> dict:
    try:
        return result.summary.to_dict()
    except AttributeError:  # not a result with a summary
        return {}


def _readable(name: Optional[str], k: int) -> str:
    if not name:
        return f"frame {k}"
    return f"frame {name}" if re.fullmatch(r"\d+", str(name)) else str(name)


def frame_names(result: Any, count: Optional[int] = None) -> list[str]:
    """The frames' names, 1st first: a TimeHistory's `frame_names`, else the summary's
    `frames[k].name` or `model.frames[k].name`, else "frame k"; `count` names at least that many."""
    names: list[str] = []
    if isinstance(result, TimeHistory):
        try:
            names = list(result.frame_names)
        except (AttributeError, KeyError, TypeError):  # a summary without frames
            names = []
    summary = _summary_dict(result)
    frames = summary.get("frames") or summary.get("model", {}).get("frames") or []
    n = max(len(names), len(frames), count or 0)
    out = []
    for k in range(n):
        given = names[k] if k < len(names) else None
        from_summary = frames[k].get("name") if k < len(frames) and isinstance(frames[k], dict) else None
        # A history's "frame k" (its fallback) gives way to a name the summary holds.
        if given and not re.fullmatch(r"frame \d+", given):
            out.append(_readable(given, k + 1))
        else:
            out.append(_readable(from_summary, k + 1))
    return out


def _name(names: Sequence[str], f: int) -> str:
    return names[f - 1] if 1 <= f <= len(names) else f"frame {f}"


_ENERGY_LABELS = {
    "input": "input by the ground motion", "kinetic": "kinetic", "storey_strain": "storey strain",
    "gap_strain": "gap-element springs", "storey_damping": "storey dashpots", "gap_damping": "gap-element dashpots",
    "impact": "lost in impacts", "storey_hysteretic": "storey hysteresis", "residual": "residual",
}

# (pattern, quantity, axis label); a_abs before a, drift_ratio before drift.
_QUANTITIES = [
    (r"u_(\d+)_(\d+)", "u", "floor displacement"),
    (r"v_(\d+)_(\d+)", "v", "floor velocity"),
    (r"a_abs_(\d+)_(\d+)", "a_abs", "absolute floor acceleration"),
    (r"a_(\d+)_(\d+)", "a", "relative floor acceleration"),
    (r"V_(\d+)", "V", "base shear"),
    (r"F_(\d+)_(\d+)(?:_(\d+))?", "F", "gap-element force"),
    (r"s_(\d+)_(\d+)(?:_(\d+))?", "s", "gap-element shortening"),
    (r"drift_ratio_(\d+)_(\d+)", "drift_ratio", "interstorey drift ratio"),
    (r"drift_(\d+)_(\d+)", "drift", "interstorey drift"),
    (r"Fs_(\d+)_(\d+)", "Fs", "storey force"),
    (r"E_(\w+)", "E", "energy"),
]
_SI = {"u": "m", "v": "m/s", "a_abs": "m/s2", "a": "m/s2", "V": "N", "F": "N", "s": "m", "drift_ratio": "1",
       "drift": "m", "Fs": "N", "E": "J"}


def _quantity(channel: str) -> tuple[str, str, tuple]:
    """(quantity, axis label, groups of the name's numbers) of a channel."""
    for pattern, quantity, label in _QUANTITIES:
        m = re.fullmatch(pattern, channel)
        if m:
            return quantity, label, m.groups()
    raise KeyError(f"{channel!r} is not a poundsim channel")


def _gap_label(names: Sequence[str], f: int, floor: int, slab: Optional[int] = None) -> str:
    """F_1_3: "<frame 1> – <frame 2>, floor 3"; F_1_5_4, a slab of the right frame's floor 4
    striking the left column below floor 5: "…, column below floor 5, slab 4"."""
    pair = f"{_name(names, f)} – {_name(names, f + 1)}"
    if slab is not None:
        return f"{pair}, column below floor {floor}, slab {slab}"
    return f"{pair}, floor {floor}"


def channel_label(channel: str, names: Sequence[str] = ()) -> str:
    """A legend's label for a channel: "8-storey frame, floor 8", "annex, storey 2",
    "8-storey frame – 4-storey block, floor 3", "kinetic"…"""
    quantity, _, g = _quantity(channel)
    if quantity == "E":
        return _ENERGY_LABELS.get(g[0], g[0].replace("_", " "))
    if quantity == "V":
        return f"{_name(names, int(g[0]))}, base"
    if quantity in ("F", "s"):
        return _gap_label(names, int(g[0]), int(g[1]), int(g[2]) if g[2] else None)
    where = "storey" if quantity in ("drift", "drift_ratio", "Fs") else "floor"
    return f"{_name(names, int(g[0]))}, {where} {g[1]}"


def _match(th: TimeHistory, patterns: Union[str, Sequence[str]]) -> list[str]:
    if isinstance(patterns, str):
        patterns = [patterns]
    chosen: list[str] = []
    for p in patterns:
        found = [p] if p in th else fnmatch.filter(th.channels, p)
        if not found:
            raise KeyError(f"no recorded channel matches {p!r}: the history has {', '.join(th.channels)} "
                           "(record others with channels=[...] in poundsim.run, or [output] channels)")
        chosen += [c for c in found if c not in chosen]
    return chosen


# --- Figures ---------------------------------------------------------------------------------

def _figsize(size: SizeArg, rows: int = 1, cols: int = 1) -> tuple[float, float]:
    if isinstance(size, str):
        try:
            w, h = SIZES[size]
        except KeyError:
            raise ValueError(f"size={size!r}: 'column', 'page' or a (width, height) tuple in inches") from None
        # Stacked axes: each further row about 2/3 the height of a single axes.
        return w, h * (1.0 + 0.65 * (rows - 1))
    w, h = size
    return float(w), float(h)


@contextlib.contextmanager
def _axes(ax: Any, size: SizeArg, rows: int = 1, cols: int = 1, **subplots: Any) -> Iterator[list]:
    """The axes to draw into: the user's (`ax`: one Axes or a sequence of rows × cols), or a new
    figure's, made and drawn under journal_style()."""
    wanted = rows * cols
    if ax is not None:
        axes = list(np.ravel(ax)) if isinstance(ax, (list, tuple, np.ndarray)) else [ax]
        if len(axes) != wanted:
            raise ValueError(f"this figure draws {wanted} axes, not {len(axes)}: pass "
                             f"{'one Axes' if wanted == 1 else f'a sequence of {wanted} Axes'} (or ax=None)")
        yield axes
        return
    import matplotlib.pyplot as plt

    with journal_style():
        fig, grid = plt.subplots(rows, cols, figsize=_figsize(size, rows, cols), dpi=DPI, layout="constrained",
                                 squeeze=False, **subplots)
        yield list(grid.ravel())


def _wrap(title: str, width_in: float, fontsize: float) -> str:
    """A title broken into lines that fit `width_in` inches (about 0.55 em a character)."""
    chars = max(20, int(width_in * 72 / (0.55 * fontsize)))
    return "\n".join(textwrap.fill(part, chars) for part in title.split("\n"))


def _finish(ax: Any, title: Optional[str]) -> None:
    if title:
        size = matplotlib.rcParams["axes.titlesize"]
        size = size if isinstance(size, (int, float)) else 10.0
        ax.set_title(_wrap(title, ax.figure.get_figwidth(), size))


def _suptitle(fig: Any, title: str) -> None:
    size = matplotlib.rcParams["axes.titlesize"]
    size = size if isinstance(size, (int, float)) else 10.0
    fig.suptitle(_wrap(title, fig.get_figwidth(), size), fontsize=size)


def time_history(th: TimeHistory, channels: Union[str, Sequence[str]], ax: Any = None, *,
                 size: SizeArg = "column", title: Optional[str] = None):
    """The chosen channels (names or fnmatch patterns: "u_*_8") against time t [s], in engineering
    units (the module's table: displacements mm, accelerations g, forces kN, drift ratios %,
    energies kJ…), one curve per channel labelled by frame name and floor ("8-storey frame,
    floor 8"). Channels of one quantity share an axes and its unit (chosen by their largest
    peak); several quantities stack one axes each, sharing t. `ax`: an Axes (one quantity) or a
    sequence of them (one per quantity). Returns the Figure."""
    chosen = _match(th, channels)
    groups: dict[str, list[str]] = {}
    for c in chosen:
        groups.setdefault(_quantity(c)[0], []).append(c)
    names = frame_names(th)
    with _axes(ax, size, rows=len(groups), sharex=True) as axes:
        for a, (quantity, members) in zip(axes, groups.items()):
            _, label, _ = _quantity(members[0])
            factor, unit = _scale(_SI[quantity], _peak([th[c] for c in members]))
            for k, c in enumerate(members):
                a.plot(th.time, th[c] * factor, color=colour(k), label=channel_label(c, names), gid=c)
            a.set_ylabel(f"{label} [{unit}]")
            a.grid(True)
            a.legend(ncol=2 if len(members) > 4 else 1)
        axes[-1].set_xlabel("t [s]")
        axes[-1].set_xlim(th.time[0], th.time[-1])
        _finish(axes[0], title)
    return axes[0].figure


def _events(th: TimeHistory, kind: str) -> np.ndarray:
    e = th.events
    if e is None or len(e) == 0:
        return np.zeros(0)
    return np.asarray(e["t"][np.asarray(e["kind"]).astype(str) == kind], dtype=float)


def gap_forces(th: TimeHistory, ax: Any = None, *, size: SizeArg = "column", title: Optional[str] = None):
    """The gap elements' forces (the F_* channels, compression positive; kN, MN above 10 MN, N
    below 1 kN) against t [s], one curve per element ("8-storey frame – 4-storey block,
    floor 3"; an element that never carried a force is drawn at 0 but left out of the legend),
    with the impacts of th.events (kind "impact", instantaneous: their impulses are not in F)
    marked | on the axis at F = 0, and locks ▼. Returns the Figure."""
    forces = [c for c in th.channels if c.startswith("F_")]
    if not forces and _summary_dict(th).get("model", {}).get("gap_elements"):
        raise KeyError("no gap-element force was recorded: pass channels=['F_*'] (poundsim.run) or add "
                       "\"F_*\" to [output] channels")
    names = frame_names(th)
    impacts, locks = _events(th, "impact"), _events(th, "lock")
    with _axes(ax, size) as (a,):
        factor, unit = _scale("N", _peak([th[c] for c in forces]))
        for k, c in enumerate(forces):
            # An element that never carried a force stays on the axis, out of the legend.
            carried = bool(np.any(th[c] != 0.0))
            a.plot(th.time, th[c] * factor, color=colour(k), label=channel_label(c, names) if carried else None,
                   gid=c)
        if len(impacts):
            a.plot(impacts, np.zeros_like(impacts), "k|", ms=6, mew=0.6, label=f"impacts ({len(impacts)})",
                   gid="impacts")
        if len(locks):
            a.plot(locks, np.zeros_like(locks), "v", color="grey", ms=3, label=f"locks ({len(locks)})", gid="locks")
        a.set_xlabel("t [s]")
        a.set_ylabel(f"gap-element force [{unit}]")
        a.set_xlim(th.time[0], th.time[-1])
        a.grid(True)
        if a.get_legend_handles_labels()[1]:
            a.legend(loc="upper left")
        _finish(a, title)
    return a.figure


def _loop(th: TimeHistory, x: str, y: str, what: str, patterns: str, ax: Any, size: SizeArg,
          title: Optional[str], xlabel: str, ylabel: str, label: str):
    missing = [c for c in (x, y) if c not in th]
    if missing:
        raise KeyError(f"{what} needs the channels {x} and {y}; {' and '.join(missing)} "
                       f"{'was' if len(missing) == 1 else 'were'} not recorded: pass channels={patterns} to "
                       "poundsim.run (or put them in [output] channels)")
    with _axes(ax, size if size != "column" else (COLUMN_WIDTH, 2.8)) as (a,):
        xs, xu = to_engineering("m", th[x])
        ys, yu = to_engineering("N", th[y])
        a.plot(xs, ys, color=colour(0), label=label, gid=y)
        a.axhline(0.0, color="black", lw=0.4)
        a.axvline(0.0, color="black", lw=0.4)
        a.set_xlabel(f"{xlabel} [{xu}]")
        a.set_ylabel(f"{ylabel} [{yu}]")
        a.grid(True)
        _finish(a, title if title is not None else label)
    return a.figure


def hysteresis(th: TimeHistory, frame: int, storey: int, ax: Any = None, *, size: SizeArg = "column",
               title: Optional[str] = None):
    """The hysteresis loop of one storey: its restoring force Fs_<frame>_<storey> (without the
    dashpot; kN, MN above 10 MN, N below 1 kN) against its drift drift_<frame>_<storey> [mm].
    Both channels must have been recorded (by default they are for frames with an inelastic
    storey law; else channels=["drift_<f>_*", "Fs_<f>_*"]); KeyError says so. Returns the Figure."""
    names = frame_names(th)
    frames = _summary_dict(th).get("model", {}).get("frames", [])
    if frames and not (1 <= frame <= len(frames) and 1 <= storey <= frames[frame - 1].get("storeys", storey)):
        raise KeyError(f"the model has no storey {storey} of frame {frame} ({len(frames)} frames of "
                       f"{', '.join(str(f.get('storeys')) for f in frames)} storeys)")
    return _loop(th, f"drift_{frame}_{storey}", f"Fs_{frame}_{storey}", f"storey {storey} of frame {frame}",
                 f"['drift_{frame}_*', 'Fs_{frame}_*']", ax, size, title, "interstorey drift", "storey force",
                 f"{_name(names, frame)}, storey {storey}")


def gap_hysteresis(th: TimeHistory, channel_suffix: str, ax: Any = None, *, size: SizeArg = "column",
                   title: Optional[str] = None):
    """The force–shortening loop of one gap element: F_<suffix> (kN, MN above 10 MN, N below 1 kN)
    against s_<suffix> [mm], the shortening past the gap (positive in contact). `channel_suffix`
    names the element as its channels do: "1_3" (frames 1–2, floor 3), "1_5_4" (a slab striking a
    column); "F_1_3" is taken too. The s_* channels are not recorded by default: pass
    channels=["F_*", "s_*"]; KeyError says so. Returns the Figure."""
    suffix = re.sub(r"^[Fs]_", "", channel_suffix)
    g = re.fullmatch(r"(\d+)_(\d+)(?:_(\d+))?", suffix)
    if not g:
        raise KeyError(f"{channel_suffix!r} names no gap element: give <frame>_<floor> as in F_1_3, or "
                       "<frame>_<floor>_<slab>")
    label = _gap_label(frame_names(th), int(g[1]), int(g[2]), int(g[3]) if g[3] else None)
    return _loop(th, f"s_{suffix}", f"F_{suffix}", f"the gap element {suffix}", f"['F_{suffix}', 's_{suffix}']",
                 ax, size, title, "shortening past the gap", "gap-element force", label)


def envelopes(th: TimeHistory, ax: Any = None, *, size: SizeArg = "page", title: Optional[str] = None):
    """Peak response over the height of every frame (summary.json's peaks.floors): the peak floor
    displacement [mm] (left axes) and the peak interstorey drift ratio [%] (right; the peak
    interstorey drift [mm] when the frames have no storey_height), against the floor, with
    pounding solid (○) and without it — the frames free, without gap elements — dashed (□).
    `ax`: a pair of Axes. Returns the Figure."""
    floors = _summary_dict(th).get("peaks", {}).get("floors", [])
    if not floors:
        raise KeyError("the summary has no peaks.floors (a time history's summary.json)")
    with_ratio = all(fl.get("interstorey_drift_ratio") is not None for fl in floors)
    names = frame_names(th)
    frames = sorted({fl["frame"] for fl in floors})
    with _axes(ax, size, cols=2, sharey=True) as (disp, drift):
        for f in frames:
            rows = sorted((fl for fl in floors if fl["frame"] == f), key=lambda fl: fl["floor"])
            levels = [fl["floor"] for fl in rows]
            c = colour(f - 1)
            u = np.array([fl["displacement_m"]["value"] for fl in rows]) * 1e3
            if with_ratio:
                d = np.array([fl["interstorey_drift_ratio"] for fl in rows]) * 100
            else:
                d = np.array([fl["interstorey_drift_m"]["value"] for fl in rows]) * 1e3
            disp.plot(u, levels, "-o", color=c, label=f"{_name(names, f)}, pounding", gid=f"u_{f}")
            drift.plot(d, levels, "-o", color=c, label=f"{_name(names, f)}, pounding", gid=f"drift_{f}")
            if all("free" in fl for fl in rows):
                uf = np.array([fl["free"]["displacement_m"] for fl in rows]) * 1e3
                key = "interstorey_drift_ratio" if with_ratio else "interstorey_drift_m"
                df = np.array([fl["free"][key] for fl in rows]) * (100 if with_ratio else 1e3)
                disp.plot(uf, levels, "--s", color=c, mfc="none", label=f"{_name(names, f)}, free",
                          gid=f"u_{f}_free")
                drift.plot(df, levels, "--s", color=c, mfc="none", label=f"{_name(names, f)}, free",
                           gid=f"drift_{f}_free")
        disp.set_xlabel("peak floor displacement [mm]")
        drift.set_xlabel("peak interstorey drift ratio [%]" if with_ratio else "peak interstorey drift [mm]")
        disp.set_ylabel("floor")
        top = max(fl["floor"] for fl in floors)
        disp.set_yticks(range(1, top + 1) if top <= 12 else range(1, top + 1, max(1, top // 8)))
        for a in (disp, drift):
            a.grid(True)
            a.set_xlim(left=0)
        disp.legend()
        if title:
            _suptitle(disp.figure, title)
    return disp.figure


_ENERGY_STACK = ["E_kinetic", "E_storey_strain", "E_gap_strain", "E_storey_hysteretic", "E_storey_damping",
                 "E_gap_damping", "E_impact"]


def energy(th: TimeHistory, ax: Any = None, *, size: SizeArg = "column", title: Optional[str] = None):
    """The energy balance in time (the E_* channels; kJ, MJ above 10 MJ, J below 1 kJ): where the
    energy is — kinetic, storey and gap-element strain, storey hysteresis — and where it went —
    storey and gap-element dashpots, impacts — stacked, under the energy the ground motion put in
    (E_input, black). Returns the Figure."""
    stack = [c for c in _ENERGY_STACK if c in th]
    if "E_input" not in th or not stack:
        raise KeyError("the energy channels were not recorded: pass channels=['E_*'] (poundsim.run) or add "
                       "\"E_*\" to [output] channels")
    factor, unit = _scale("J", _peak([th["E_input"]] + [th[c] for c in stack]))
    with _axes(ax, size) as (a,):
        a.stackplot(th.time, *[th[c] * factor for c in stack], labels=[channel_label(c) for c in stack],
                    colors=[colour(k) for k in range(len(stack))], alpha=0.75, lw=0)
        a.plot(th.time, th["E_input"] * factor, "k", lw=1.0, label=channel_label("E_input"), gid="E_input")
        a.set_xlabel("t [s]")
        a.set_ylabel(f"energy [{unit}]")
        a.set_xlim(th.time[0], th.time[-1])
        a.set_ylim(0, 1.35 * max(_peak([th["E_input"] * factor]), 1e-300))  # room for the legend
        a.grid(True)
        a.legend(loc="upper left", ncol=2)
        _finish(a, title)
    return a.figure


# --- Frequency responses ---------------------------------------------------------------------

def _frf_frames(table: Table) -> list[int]:
    return sorted(int(m[1]) for m in (re.fullmatch(r"V(\d+)_W", n) for n in table.names) if m)


def _rows(table: Table, branch: Optional[str] = None) -> np.ndarray:
    """Row indices (of `branch`, or all), sorted by ω̄/ω₁."""
    idx = np.arange(len(table))
    if branch is not None:
        if "branch" in table:
            idx = idx[np.asarray(table["branch"]).astype(str) == branch]
        elif branch != "rest":  # a table without branches holds responses from rest
            idx = idx[:0]
    return idx[np.argsort(table["ratio"][idx], kind="stable")]


def _continued_branches(a: Any, table: Table, frames: Sequence[int], names: Any, label: str,
                        x: str = "ratio") -> None:
    """The branches of a response by continuation against column `x`: stable solid, unstable
    dashed, bifurcations marked (see frf)."""
    branch = np.asarray(table["branch"]).astype(str)
    ids = np.asarray(table["branch_id"])
    stable = np.asarray(table["stable"]) == 1
    kinds = np.asarray(table["bifurcation"]).astype(str)
    ratio = np.asarray(table[x])
    for i, f in enumerate(frames):
        c = colour(f - 1)
        v = np.asarray(table[f"V{f}_W"])
        labelled = {True: False, False: False}
        for b in np.unique(ids[branch == "continuation"]):
            rows = np.flatnonzero((branch == "continuation") & (ids == b))  # in arclength order
            start = 0
            for j in range(1, len(rows) + 1):
                if j < len(rows) and stable[rows[j]] == stable[rows[start]]:
                    continue
                run = rows[start:min(j + 1, len(rows))]  # overlapping by one point: a continuous curve
                s = bool(stable[rows[start]])
                a.plot(ratio[run], v[run], "-" if s else "--", color=c, lw=1.1 if s else 0.8,
                       label=(f"{_name(names, f)}, {label}" if s else f"{_name(names, f)}, unstable")
                       if not labelled[s] else None, gid=f"V{f}_W_branch{b}_{'stable' if s else 'unstable'}")
                labelled[s] = True
                start = j
        for kind, marker in (("fold", "o"), ("period-doubling", "s"), ("Neimark-Sacker", "D")):
            rows = np.flatnonzero(kinds == kind)
            if len(rows):
                a.plot(ratio[rows], v[rows], marker, color=c, ms=3.2, mfc="none", mew=0.7,
                       label=kind if i == 0 else None, gid=f"V{f}_W_{kind}")


def _finish_shear_axes(a: Any, x: np.ndarray, xlabel: str, title: Optional[str]) -> None:
    """V/W from 0 against `x` over its range, gridded, with the legend and the title."""
    a.set_xlabel(xlabel)
    a.set_ylabel("V / W")
    a.set_xlim(float(np.nanmin(x)), float(np.nanmax(x)))
    a.set_ylim(bottom=0)
    a.grid(True)
    a.legend(ncol=2)
    _finish(a, title)


def frf(fr: FrequencyResponse, ax: Any = None, free: bool = True, *, sweep: Optional[FrequencyResponse] = None,
        compare: Optional[FrequencyResponse] = None, compare_label: str = "compared", label: str = "interacting",
        size: SizeArg = "column", title: Optional[str] = None):
    """V/W (steady-state peak base shear K₁u₁ over the weight of frame 1) against ω̄/ω₁, as the
    paper's Figures 2–4: every frame (frame 1 blue, frame 2 red) interacting solid — the
    responses from rest, branch "rest" — and free dashed (`free=False` leaves them out);
    responses that are not periodic (periodicity 0) marked ×. A response by continuation
    (frf.method = "continuation") draws each branch in its order along the arclength, stable
    stretches solid and unstable ones dashed, its folds ○, period doublings □ and Neimark–Sacker
    points ◇ marked, the points it simulated +, and the free frames dotted. A two-way sweep's branches "up"
    and "down" (in `fr` itself, or in `sweep`) are drawn as markers ▲ and ▼ over the curves;
    `compare`, another response (bare pounding, say), dotted with `compare_label`; `label` names
    the solid curves. Legend labels: "<frame>, interacting", "<frame>, free". Returns the
    Figure."""
    table = fr.table
    if len(table) == 0:
        raise ValueError("the frequency response has no rows")
    frames = _frf_frames(table)
    names = frame_names(fr, len(frames))
    rest = _rows(table, "rest")
    continued = "branch_id" in table
    curve = rest if len(rest) and not continued else _rows(table)  # a sweep alone: its free curve from every row
    with _axes(ax, size if size != "column" else (COLUMN_WIDTH, 2.8)) as (a,):
        ratio = table["ratio"]
        chaotic = rest[table["periodicity"][rest] == 0] if "periodicity" in table else rest[:0]
        if continued:
            _continued_branches(a, table, frames, names, label)
        for i, f in enumerate(frames):
            c = colour(f - 1)
            if len(rest) and continued:
                a.plot(ratio[rest], table[f"V{f}_W"][rest], "+", color=c, ms=3.5,
                       label="simulated" if i == 0 else None, gid=f"V{f}_W_simulated")
            elif len(rest):
                a.plot(ratio[rest], table[f"V{f}_W"][rest], "-", color=c, lw=1.1,
                       label=f"{_name(names, f)}, {label}", gid=f"V{f}_W")
            if free:
                order = curve[np.unique(ratio[curve], return_index=True)[1]]
                # Beside a continuation's dashed unstable branches the free frames are dotted.
                a.plot(ratio[order], table[f"V{f}_free_W"][order], ":" if continued else "--", color=c, lw=0.8,
                       label=f"{_name(names, f)}, free", gid=f"V{f}_free_W")
            if len(chaotic):
                a.plot(ratio[chaotic], table[f"V{f}_W"][chaotic], "x", color=c, ms=3.5,
                       label="not periodic" if i == 0 else None, gid=f"V{f}_W_not_periodic")
        if compare is not None:
            other = compare.table
            rows = _rows(other, "rest")
            rows = rows if len(rows) else _rows(other)
            for f in _frf_frames(other):
                a.plot(other["ratio"][rows], other[f"V{f}_W"][rows], ":", color=colour(f - 1), lw=1.0,
                       label=f"{_name(names, f)}, {compare_label}", gid=f"V{f}_W_compare")
        for source in (fr, sweep):
            if source is None:
                continue
            t = source.table
            for branch, marker, name in (("up", "^", "sweep up"), ("down", "v", "sweep down")):
                rows = _rows(t, branch)
                if not len(rows):
                    continue
                for i, f in enumerate(_frf_frames(t)):
                    a.plot(t["ratio"][rows], t[f"V{f}_W"][rows], marker, ms=2.6, mfc="none", mew=0.5,
                           color=colour(f - 1), label=name if i == 0 else None, gid=f"V{f}_W_{branch}")
        _finish_shear_axes(a, ratio, "ω̄ / ω₁", title)
    return a.figure


def continuation(c: Continuation, ax: Any = None, free: bool = True, *, size: SizeArg = "column",
                 title: Optional[str] = None):
    """V/W against the continued model parameter (analysis.kind = "continuation",
    [periodic-orbits.md]): every frame's branches, stable solid and unstable dashed, folds ○,
    period doublings □ and Neimark–Sacker points ◇ marked, the free frames dotted (`free=False`
    leaves them out). The x axis is named by the parameter's key. Returns the Figure."""
    table = c.table
    if len(table) == 0:
        raise ValueError("the continuation has no rows")
    frames = _frf_frames(table)
    names = frame_names(c, len(frames))
    key = _summary_dict(c).get("parameter", {}).get("key", "parameter")
    x = np.asarray(table["parameter"])
    with _axes(ax, size if size != "column" else (COLUMN_WIDTH, 2.8)) as (a,):
        _continued_branches(a, table, frames, names, "interacting", x="parameter")
        if free:
            order = np.argsort(x, kind="stable")
            for f in frames:
                a.plot(x[order], table[f"V{f}_free_W"][order], ":", color=colour(f - 1), lw=0.8,
                       label=f"{_name(names, f)}, free", gid=f"V{f}_free_W")
        _finish_shear_axes(a, x, parameter_label(key), title)
    return a.figure


# --- Studies, ensembles, optimisations -------------------------------------------------------

_PARAMETER_LABELS = {
    "model.dimensionless.eta": "η = k / K₁", "model.dimensionless.mu": "μ = c / (M₁λ)",
    "model.dimensionless.epsilon": "ε̄ = ελ² / g", "model.dimensionless.delta": "δ̄ = δλ² / g",
    "model.dimensionless.restitution": "e", "model.dimensionless.alpha": "α = K₂ / K₁",
    "model.dimensionless.beta": "β = M₂ / M₁", "model.dimensionless.gamma": "γ = C₂ / C₁",
    "model.dimensionless.xi": "ξ", "excitation.ratio": "ω̄ / ω₁", "excitation.amplitude_g": "amplitude [g]",
    # The unit of a stiffness depends on the law (N/m, N/m^1.5 for Hertz's): left out.
    "gap_elements.stiffness": "gap-element stiffness k", "gap_elements.damping": "gap-element damping c [N·s/m]",
    "gap_elements.gap": "gap δ [m]", "gap_elements.shortening": "gap-element shortening ε [m]",
    "gap_elements.restitution": "e", "gap_elements.joint_width": "joint width w [m]",
    "excitation.scale": "record scale", "excitation.file": "record",
}


def parameter_label(key: str) -> str:
    """An axis label for a study's parameter key: the paper's symbol for the dimensionless ones
    ("η = k / K₁"), a name with its unit for the usual physical ones ("gap-element damping c
    [N·s/m]"), else the key's last part in words and where it is ("storey height (frames[2])")."""
    if key in _PARAMETER_LABELS:
        return _PARAMETER_LABELS[key]
    where, _, last = key.rpartition(".")
    return f"{last.replace('_', ' ')} ({where.replace('_', ' ')})" if where else key.replace("_", " ")


# The figures of merit (docs/studies.md) in words, longer stems before the stems they begin with;
# around a stem the prefixes max_ (the worse frame, the largest element; twice: the worst record
# of an ensemble), free_ and bare_, and after it the frame, floor or element's numbers and the
# unit's suffix (results.column_unit's).
_METRIC_WORDS = [
    ("peak_drift_ratio", "peak drift ratio"), ("residual_drift_ratio", "residual drift ratio"),
    ("peak_drift", "peak drift"), ("residual_drift", "residual drift"),
    ("peak_abs_acc", "peak absolute acceleration"), ("peak_u", "peak floor displacement"),
    ("peak_V_W", "peak V/W"), ("peak_V_at", "ω̄ / ω₁ of the peak V/W"),
    ("ratio_to_free", "peak V/W ÷ free frame's"), ("ratio_to_bare", "peak V/W ÷ bare pounding's"),
    ("amp_u", "peak displacement ÷ free frame's"), ("amp_drift", "peak drift ÷ free frame's"),
    ("amp_acc", "peak absolute acceleration ÷ free frame's"), ("min_gap", "free frames' largest approach"),
    ("gap_force", "gap-element force"), ("stroke_use", "stroke use"), ("hysteretic_energy", "hysteretic energy"),
    ("impact_impulse", "impulse of an impact"), ("impacts", "impacts"), ("energy_residual", "energy residual"),
    ("pga", "PGA"), ("non_periodic", "non-periodic responses"), ("points", "frequencies"),
]
_ELEMENT_METRICS = ("min_gap", "gap_force", "stroke_use")
_STOREY_METRICS = ("peak_drift_ratio", "peak_drift", "amp_drift")


def _metric(name: str, values: Any = ()) -> tuple[float, str]:
    """(factor, axis label) of a figure of merit: its values times factor are drawn in the label's
    unit, drift ratios in % and the SI units as `to_engineering` converts them (chosen by the
    values' peak); other ratios as they are."""
    unit = column_unit(name)
    v = np.asarray(values).ravel()
    v = v[np.isfinite(v)] if _numeric(v) else np.zeros(0)
    if "drift_ratio" in name:
        factor, shown = 100.0, "%"
    elif unit in ("", "1"):
        factor, shown = 1.0, ""
    else:
        factor, shown = _scale(unit, float(np.abs(v).max()) if v.size else 0.0)
    stem = re.sub(r"V(\d+)_(W|at)$", r"V_\2_\1", name)
    stem = re.sub(r"_(rad_s|m_s2|m_s|m|s|Ns|N|J|g)$", "", stem)
    m = re.fullmatch(r"((?:max_)*)(free_|bare_)?(.*?)((?:_\d+)*)", stem)
    worse, variant, stem, numbers = m.group(1).count("max_"), m.group(2), m.group(3), m.group(4)
    words = dict(_METRIC_WORDS).get(stem, stem.replace("_", " "))
    n = [int(k) for k in numbers.split("_")[1:]]
    if stem in _ELEMENT_METRICS and len(n) >= 2:
        words += ", " + _gap_label((), n[0], n[1], n[2] if len(n) > 2 else None)
    elif len(n) == 2:
        words += f", frame {n[0]}, {'storey' if stem in _STOREY_METRICS else 'floor'} {n[1]}"
    elif len(n) == 1:
        words += f", frame {n[0]}"
    if variant:
        words += ", without gap elements" if variant == "free_" else ", bare pounding"
    if worse:
        words += ", largest element" if stem in _ELEMENT_METRICS else ", largest" if stem == "impact_impulse" \
            else ", worse frame"
    if worse > 1:
        words += ", worst record"
    return factor, f"{words} [{shown}]" if shown else words


def metric_label(name: str, values: Any = ()) -> str:
    """An axis label for a figure of merit (a column of a study's table): its name in words with
    its unit, "max_peak_drift_ratio" → "peak drift ratio, worse frame [%]", "peak_abs_acc_2_g" →
    "peak absolute acceleration, frame 2 [g]"; `values` choose among kN, MN… as `to_engineering`
    does."""
    return _metric(name, values)[1]


def _short(v: float, digits: int = 3) -> str:
    """A number to `digits` significant digits, an exponent without its + and leading 0s:
    "0.0123", "3.16e6" (not "3.16228e+06")."""
    if v == 0:
        return "0"
    mantissa, e, exponent = f"{v:.{digits}g}".partition("e")
    return f"{mantissa}e{int(exponent)}" if e else mantissa


def _tick_labels(values: np.ndarray) -> list[str]:
    """The labels of a parameter's values: numbers as short as they stay distinct, text as it is."""
    if not _numeric(values):
        return [str(v) for v in values]
    for digits in range(3, 17):
        labels = [_short(float(v), digits) for v in values]
        if len(set(labels)) == len(set(values.tolist())):
            break
    return labels


def _done(study: Study) -> np.ndarray:
    t = study.table
    if "status" not in t:
        return np.arange(len(t))
    return np.flatnonzero(np.asarray(t["status"]).astype(str) == "done")


def _edges(values: np.ndarray) -> tuple[np.ndarray, bool]:
    """Cell edges around grid values (midpoints; geometric ones for a log-spaced axis) and
    whether the axis is logarithmic."""
    v = np.asarray(values, dtype=float)
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5]), False
    log = len(v) >= 3 and v[0] > 0 and np.allclose(np.diff(np.log(v)), np.log(v[1] / v[0]), rtol=1e-6) \
        and not np.allclose(np.diff(v), v[1] - v[0], rtol=1e-6)
    w = np.log(v) if log else v
    mid = (w[1:] + w[:-1]) / 2
    e = np.concatenate([[w[0] - (mid[0] - w[0])], mid, [w[-1] + (w[-1] - mid[-1])]])
    return (np.exp(e) if log else e), log


def _numeric(column: np.ndarray) -> bool:
    return np.issubdtype(np.asarray(column).dtype, np.number)


def study_map(study: Study, x: str, y: str, metric: str, ax: Any = None, *, fix: Optional[dict] = None,
              annotate: bool = True, spacing: str = "even", cmap: str = "viridis_r", size: SizeArg = "column",
              title: Optional[str] = None):
    """A heat map of `metric` (a column of the study's table: "max_ratio_to_bare", …) over two of
    a grid study's parameters, x and y (table columns: "model.dimensionless.eta"), from its
    finished points; `fix` {key: value} selects the points where other varied parameters hold
    that value. One pcolormesh cell per grid point: evenly spaced, ticked with the parameter's
    values (`spacing="even"`, readable for any grid), or for numeric parameters centred on their
    values (`spacing="value"`; a log-spaced axis on a log scale); a missing or failed point is
    blank. The axes are named by `parameter_label`, the colour bar by `metric_label` (drift
    ratios in %, SI figures as `to_engineering` converts them, other ratios as they are). Each
    cell shows its value to 3 significant digits (`annotate`), the lowest is outlined red. The
    mesh's array (`fig.axes[0].collections[0].get_array()`) is the metric on the grid in the
    colour bar's unit, rows y and columns x, both ascending. ValueError when the points are not
    one per (x, y). Returns the Figure."""
    if spacing not in ("even", "value"):
        raise ValueError(f"spacing={spacing!r}: 'even' or 'value'")
    t = study.table
    for key in (x, y, metric):
        if key not in t:
            raise ValueError(f"the study has no column {key!r} (it has {', '.join(t.names)})")
    rows = _done(study)
    rows = rows[np.isfinite(np.asarray(t[metric][rows], dtype=float))] if _numeric(t[metric]) else rows[:0]
    for key, value in (fix or {}).items():
        if key not in t:
            raise ValueError(f"fix: the study has no parameter {key!r}")
        col = t[key][rows]
        if _numeric(col) and isinstance(value, (int, float)) and not isinstance(value, bool):
            rows = rows[np.isclose(col.astype(float), float(value), rtol=1e-12, atol=0.0)]
        else:
            rows = rows[np.asarray(col).astype(str) == str(value)]
    if not len(rows):
        raise ValueError(f"no finished point with metric {metric}")
    xs_all, ys_all = t[x][rows], t[y][rows]
    xs, ys = np.unique(xs_all), np.unique(ys_all)
    grid = np.full((len(ys), len(xs)), np.nan)
    for r, xv, yv in zip(rows, xs_all, ys_all):
        j, i = np.searchsorted(ys, yv), np.searchsorted(xs, xv)
        if np.isfinite(grid[j, i]):
            raise ValueError(f"several points at {x} = {xv}, {y} = {yv}; fix the other parameters (fix=…, --fix)")
        grid[j, i] = float(t[metric][r])
    factor, label = _metric(metric, grid)
    grid = grid * factor
    with _axes(ax, size if size != "column" else (COLUMN_WIDTH, 2.9)) as (a,):
        centres = []
        for axis, values in (("x", xs), ("y", ys)):
            set_ticks = a.set_xticks if axis == "x" else a.set_yticks
            if spacing == "value" and _numeric(values):
                edges, log = _edges(values)
                if log:
                    (a.set_xscale if axis == "x" else a.set_yscale)("log")
                centres.append((np.asarray(values, dtype=float), edges))
            else:
                centres.append((np.arange(len(values), dtype=float), np.arange(len(values) + 1) - 0.5))
            if spacing != "value" or not _numeric(values) or len(values) <= 12:
                step = max(1, len(values) // 12)
                set_ticks(centres[-1][0][::step], _tick_labels(values)[::step])
            elif not log:  # Matplotlib's ticks, short (a log axis has its own: 10⁶)
                (a.xaxis if axis == "x" else a.yaxis).set_major_formatter(FuncFormatter(lambda v, _: _short(v)))
        a.minorticks_off()
        (cx, ex), (cy, ey) = centres
        mesh = a.pcolormesh(ex, ey, np.ma.masked_invalid(grid), cmap=cmap, shading="flat")
        j, i = np.unravel_index(np.nanargmin(grid), grid.shape)
        if annotate:
            lo, hi = np.nanmin(grid), np.nanmax(grid)
            for jj in range(len(ys)):
                for ii in range(len(xs)):
                    v = grid[jj, ii]
                    if np.isfinite(v):
                        a.text(cx[ii], cy[jj], _short(v), ha="center", va="center", fontsize=5.5,
                               color="white" if v > (lo + hi) / 2 else "black",
                               fontweight="bold" if (jj, ii) == (j, i) else "normal")
        from matplotlib.patches import Rectangle

        a.add_patch(Rectangle((ex[i], ey[j]), ex[i + 1] - ex[i], ey[j + 1] - ey[j], fill=False, lw=1.2, ec="red",
                              gid="lowest"))
        a.set_xlabel(parameter_label(x))
        a.set_ylabel(parameter_label(y))
        a.figure.colorbar(mesh, ax=a, label=label, format=FuncFormatter(lambda v, _: _short(v)))
        _finish(a, title)
    return a.figure


def _record_label(study: Study, row: int) -> str:
    params = study.parameters
    if params and params[0] in study.table:
        value = str(study.table[params[0]][row])
        return os.path.splitext(os.path.basename(value))[0] if "/" in value or "." in value else value
    return f"point {study.table['id'][row]}" if "id" in study.table else f"point {row + 1}"


_MARKERS = ["o", "s", "^", "D", "v", "P", "X", "<", ">", "*"]


def ensemble_amplification(study: Study, ax: Any = None, *, size: SizeArg = "column",
                           title: Optional[str] = None):
    """Amplification by pounding over an ensemble of records (or the points of a study): per
    frame, each record's ratio of the peak base shear with pounding to the free frame's
    (ratio_to_free_<f>: above 1, pounding makes it worse) as a marker, one marker per record,
    and their mean as a bar; the line at 1 is no change. Returns the Figure."""
    t = study.table
    frames = sorted(int(m[1]) for m in (re.fullmatch(r"ratio_to_free_(\d+)", n) for n in t.names) if m)
    if not frames:
        raise KeyError("the study has no ratio_to_free_<frame> columns (each = \"time_history\" or an ensemble)")
    rows = _done(study)
    if not len(rows):
        raise ValueError("no finished record")
    names = frame_names(study, max(frames))
    with _axes(ax, size) as (a,):
        x = np.arange(len(frames), dtype=float)
        means = np.array([np.nanmean(t[f"ratio_to_free_{f}"][rows].astype(float)) for f in frames])
        a.bar(x, means, 0.6, color=[colour(f - 1) for f in frames], alpha=0.35, label="mean", gid="mean")
        spread = np.linspace(-0.2, 0.2, len(rows)) if len(rows) > 1 else np.zeros(1)
        for k, r in enumerate(rows):
            a.plot(x + spread[k], [t[f"ratio_to_free_{f}"][r] for f in frames], _MARKERS[k % len(_MARKERS)],
                   color="black", mfc="none", ms=3.2, mew=0.6, ls="none", label=_record_label(study, r),
                   gid=f"record_{k}")
        a.axhline(1.0, color="black", lw=0.6)
        a.set_xticks(x, [_name(names, f) for f in frames])
        a.set_ylabel("peak base shear: pounding ÷ free")
        a.set_ylim(0, 1.1 * max(1.0, float(np.nanmax([t[f"ratio_to_free_{f}"][rows] for f in frames]))))
        a.grid(True, axis="y")
        a.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), borderaxespad=0.3)  # beside: record names are long
        _finish(a, title)
    return a.figure


def ensemble_floor_amplification(study: Study, ax: Any = None, *, size: SizeArg = "page",
                                 title: Optional[str] = None):
    """Amplification by pounding per frame and floor over an ensemble of records: the ratio of the
    peak with pounding to the peak without it (amp_u_, amp_drift_, amp_acc_<f>_<floor>) of the
    displacement, the interstorey drift and the absolute acceleration, as the mean over the
    records (bars) and the largest (▼). Returns the Figure."""
    t = study.table
    rows = _done(study)
    keys = sorted((m.groups() for m in (re.fullmatch(r"amp_u_(\d+)_(\d+)", n) for n in t.names) if m),
                  key=lambda g: (int(g[0]), int(g[1])))
    if not keys:
        raise KeyError("the study has no amp_u_<frame>_<floor> columns (an ensemble of time histories)")
    if not len(rows):
        raise ValueError("no finished record")
    names = frame_names(study, max(int(f) for f, _ in keys))
    with _axes(ax, size) as (a,):
        width = 0.26
        highest = 1.0
        for q, (prefix, name) in enumerate((("amp_u", "displacement"), ("amp_drift", "interstorey drift"),
                                            ("amp_acc", "absolute acceleration"))):
            cols = [f"{prefix}_{f}_{i}" for f, i in keys]
            if not all(c in t for c in cols):
                continue
            values = np.array([t[c][rows].astype(float) for c in cols])
            mean, worst = np.nanmean(values, axis=1), np.nanmax(values, axis=1)
            highest = max(highest, float(np.nanmax(worst)))
            x = np.arange(len(keys)) + (q - 1) * width
            a.bar(x, mean, width, color=colour(q), label=name, gid=f"{prefix}_mean")
            a.plot(x, worst, "v", color=colour(q), mec="black", mew=0.4, ms=3.5, ls="none", gid=f"{prefix}_largest")
        a.axhline(1.0, color="black", lw=0.6)
        a.set_xticks(range(len(keys)), [f"{_name(names, int(f))}\nfloor {i}" for f, i in keys])
        a.plot([], [], "v", color="white", mec="black", mew=0.4, ms=3.5, ls="none", label="largest (bars: mean)")
        a.set_ylabel("peak with pounding ÷ peak without")
        a.set_ylim(0, 1.45 * highest)  # room for the legend above the bars
        a.grid(True, axis="y")
        a.legend(ncol=2, loc="upper center")
        _finish(a, title)
    return a.figure


_DESIGN_NAMES = {"ec8_type1": "EN 1998-1 type 1", "ec8_type2": "EN 1998-1 type 2", "table": "design spectrum"}


def spectra(study: Study, ax: Any = None, *, size: SizeArg = "page", title: Optional[str] = None):
    """The 5 % (or the scaling's damping) pseudo-acceleration spectra of an ensemble's records as
    scaled by [ensemble.scaling] (study.spectra, spectra.csv): each record thin, their mean thick,
    the design spectrum dashed, and what was matched — the period range shaded, or the period of
    S_a marked. Log period axis. Returns the Figure."""
    if study.spectra is None:
        raise ValueError("the ensemble has no spectra (it was not run with [ensemble.scaling])")
    t = study.spectra
    period = np.asarray(t["period_s"], dtype=float)
    records = sorted((int(m.group(1)) for m in (re.fullmatch(r"sa_(\d+)_g", n) for n in t.names) if m))
    scaling = _summary_dict(study).get("scaling", {})
    files = [r.get("record", "") for r in scaling.get("records", [])]
    with _axes(ax, size) as (a,):
        for i in records:
            name = os.path.splitext(os.path.basename(files[i - 1]))[0] if i <= len(files) else f"record {i}"
            a.plot(period, t[f"sa_{i}_g"], lw=0.7, color=colour(i - 1), alpha=0.8, label=name, gid=f"record_{i}")
        a.plot(period, t["mean_g"], lw=1.8, color="black", label="mean", gid="mean")
        if "target_g" in t:
            a.plot(period, t["target_g"], lw=1.2, ls="--", color="black",
                   label=_DESIGN_NAMES.get(scaling.get("design", ""), "target"), gid="target")
        if "range_s" in scaling:
            lo, hi = scaling["range_s"]
            a.axvspan(lo, hi, color="0.85", zorder=0, label="matched range", gid="range")
        elif "period_s" in scaling:
            a.axvline(scaling["period_s"], color="0.5", lw=0.8, ls=":", label="period of S_a", gid="period")
        a.set_xscale("log")
        a.set_xlabel("period T [s]")
        a.set_ylabel(f"S_a [g], ζ = {scaling.get('damping', 0.05):g}")
        a.grid(True, which="both", lw=0.3)
        a.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), borderaxespad=0.3)  # beside: record names are long
        _finish(a, title)
    return a.figure


def optimization(opt: Optimization, ax: Any = None, *, size: SizeArg = "column", title: Optional[str] = None):
    """An optimisation's outcome. With a frequency-response objective (opt.optimum_frf and
    opt.bare_frf): V/W against ω̄/ω₁ of every frame for the optimum gap elements (solid), for
    bare pounding at the joint width (dotted) and free (dashed). Otherwise the objective of every
    evaluation (○, coloured by stage; rejected and failed ones left out; in `metric_label`'s unit,
    drift ratios in %), those that break a
    constraint (evaluations.csv's feasible = 0) as grey × labelled "infeasible", the best
    feasible so far (line, from the first feasible evaluation) and the optimum, the best feasible
    evaluation (★); when none is feasible, no optimum and the legend says so. Returns the Figure."""
    if opt.optimum_frf is not None:
        optimum = FrequencyResponse(opt.optimum_frf, {})
        bare = FrequencyResponse(opt.bare_frf, {}) if opt.bare_frf is not None else None
        return frf(optimum, ax, compare=bare, compare_label="bare pounding", label="optimum", size=size,
                   title=title)
    ev = opt.evaluations
    summary = _summary_dict(opt)
    metric = summary.get("comparison", {}).get("objective", {}).get("metric") \
        or summary.get("analysis", {}).get("objective", "objective")
    n = np.asarray(ev["evaluation"], dtype=float) if "evaluation" in ev else np.arange(1, len(ev) + 1, dtype=float)
    obj = np.asarray(ev["objective"], dtype=float)
    ok = np.isfinite(obj) & (obj < 1e29)
    if "status" in ev:
        ok &= np.asarray(ev["status"]).astype(str) == "done"
    # With constraints the table says which evaluations meet them; one that does not is no
    # candidate, however low its objective (the optimiser's optimum is feasible too).
    feasible = ok & (np.asarray(ev["feasible"]) == 1) if "feasible" in ev else ok
    infeasible = ok & ~feasible
    factor, ylabel = _metric(metric, obj[ok])
    obj = obj * factor
    with _axes(ax, size) as (a,):
        stages = np.asarray(ev["stage"]).astype(str) if "stage" in ev else np.full(len(ev), "")
        for k, stage in enumerate(dict.fromkeys(stages)):
            sel = feasible & (stages == stage)
            if sel.any():
                a.plot(n[sel], obj[sel], "o", color=colour(k), mfc="none", ms=3, ls="none", label=stage or None,
                       gid=f"stage_{stage}")
        if infeasible.any():
            a.plot(n[infeasible], obj[infeasible], "x", color="0.6", ms=3, mew=0.6, ls="none", label="infeasible",
                   gid="infeasible")
        best = np.minimum.accumulate(np.where(feasible, obj, np.inf))
        shown = np.isfinite(best)
        if shown.any():
            a.step(n[shown], best[shown], where="post", color="black", lw=0.8, label="best so far", gid="best")
            k = int(np.flatnonzero(feasible)[np.argmin(obj[feasible])])
            a.plot([n[k]], [obj[k]], "*", color="black", ms=7, label="optimum", gid="optimum")
        a.set_xlabel("evaluation")
        a.set_ylabel(ylabel)
        a.grid(True)
        a.legend(title=None if feasible.any() else "no feasible evaluation: no optimum")
        _finish(a, title)
    return a.figure


def pareto(opt: Optimization, ax: Any = None, *, size: SizeArg = "column", title: Optional[str] = None,
           reference: Optional[dict[str, tuple[float, float]]] = None):
    """The Pareto front of an optimisation with [optimize.pareto] (opt.pareto, pareto.csv): the
    objective against the second figure at each point, the non-dominated ones joined (●), the
    dominated ones apart (○), the infeasible ones grey (×), and each point's limit on the second
    figure as a dotted vertical, both figures named and scaled by `metric_label` (drift ratios in
    %). `reference`: other designs to mark, label → (second figure, objective) as pareto.csv has
    them, e.g. bare pounding and the free frames. Returns the Figure."""
    if opt.pareto is None:
        raise ValueError("the optimisation has no Pareto front (no [optimize.pareto])")
    t = opt.pareto
    names = [n for n in t.names if n not in ("point", "limit", "feasible", "dominated")]
    objective, metric = names[0], names[1]
    fx, xlabel = _metric(metric, t[metric])
    fy, ylabel = _metric(objective, t[objective])
    x = np.asarray(t[metric], dtype=float) * fx
    y = np.asarray(t[objective], dtype=float) * fy
    feasible = np.asarray(t["feasible"]) == 1
    front = (np.asarray(t["dominated"]) == 0) & feasible
    limit = np.asarray(t["limit"], dtype=float) * fx
    with _axes(ax, size) as (a,):
        order = np.argsort(x[front])
        a.plot(x[front][order], y[front][order], "o-", color=colour(0), ms=4, lw=1.2, label="Pareto front", gid="front")
        dominated = ~front & feasible
        if dominated.any():
            a.plot(x[dominated], y[dominated], "o", color=colour(0), mfc="none", ms=4, ls="none", label="dominated",
                   gid="dominated")
        if (~feasible).any():
            a.plot(x[~feasible], y[~feasible], "x", color="0.6", ms=4, mew=0.7, ls="none", label="infeasible",
                   gid="infeasible")
        for e in limit[np.isfinite(limit)]:
            a.axvline(e, color="0.6", lw=0.5, ls=":", zorder=0)
        for k, (label, (rx, ry)) in enumerate((reference or {}).items()):
            a.plot([rx * fx], [ry * fy], "sD^v"[k % 4], color=colour(k + 1), ms=5, ls="none", label=label,
                   gid=f"reference_{k}")
        a.set_xlabel(xlabel)
        a.set_ylabel(ylabel)
        a.grid(True, lw=0.3)
        a.legend()
        _finish(a, title)
    return a.figure


def compare_runs(ths: Sequence[TimeHistory], labels: Optional[Sequence[str]] = None, ax: Any = None, *,
                 size: SizeArg = "page", title: Optional[str] = None):
    """Time histories of the same frames side by side (contact laws, say), from their summaries:
    the peak gap-element force (kN, MN above 10 MN, N below 1 kN), the peak base shear V/W of
    each frame (W the weight of frame 1, the paper's normalisation) and the energy dissipated by
    the gap elements — their dashpots and the impacts' losses (kJ, MJ, J as the forces). `labels`
    name the runs (default: their titles). `ax`: three Axes. Returns the Figure."""
    if not ths:
        raise ValueError("no time history to compare")
    summaries = [_summary_dict(th) for th in ths]
    labels = list(labels) if labels is not None else [s.get("title") or f"run {k + 1}" for k, s in enumerate(summaries)]
    force = np.array([s["max_gap_force_N"] for s in summaries], dtype=float)
    shear = [[b["over_frame1_weight"] for b in s["peaks"]["base_shear"]] for s in summaries]
    dissipated = np.array([s["energy"]["gap_damping_J"] + s["energy"]["impact_loss_J"] for s in summaries])
    frames = max(len(v) for v in shear)
    shear = [v + [np.nan] * (frames - len(v)) for v in shear]  # runs of fewer frames
    names = frame_names(ths[0], frames)
    x = np.arange(len(ths))
    with _axes(ax, size, cols=3) as (af, av, ae):
        fv, fu = to_engineering("N", force)
        af.bar(x, fv, color=[colour(i) for i in x], gid="force")
        af.set_ylabel(f"peak gap-element force [{fu}]")
        width = 0.8 / frames
        for f in range(frames):
            av.bar(x + (f - (frames - 1) / 2) * width, [s[f] for s in shear], width, color=colour(f),
                   label=names[f], gid=f"V{f + 1}_W")
        av.set_ylabel("peak base shear V / W")
        av.legend()
        ev, eu = to_engineering("J", dissipated)
        ae.bar(x, ev, color=[colour(i) for i in x], gid="dissipated")
        ae.set_ylabel(f"dissipated by the gap elements [{eu}]")
        for a in (af, av, ae):
            a.set_xticks(x, [textwrap.fill(str(label), 14) for label in labels], fontsize=6)
            a.grid(True, axis="y")
        if title:
            _suptitle(af.figure, title)
    return af.figure
