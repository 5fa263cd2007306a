"""poundsim.plot on the command line's result folders (read by poundsim.read): every figure is a
PNG of the journal's size, and what it draws are the results' numbers in engineering units — the
plotted data checked against history.csv, summary.json and the tables' CSV text. Also poundsim.read's
tables against their CSV text, and the plotting scripts' command lines (docs/python.md)."""

import json
import os
import pathlib
import re
import runpy
import struct
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import poundsim  # noqa: E402
from poundsim import plot as pp  # noqa: E402

from support import EXAMPLES, SOURCE, cli_run, read_csv  # noqa: E402

SCRIPTS = SOURCE / "python"
G = 9.81  # poundsim's standard_gravity (include/poundsim/units.hpp)
CHANNELS = '["u_*", "v_*", "a_abs_*", "V_*", "F_*", "s_*", "drift_*", "E_*"]'  # drift_* takes drift_ratio_*


def bare_name(column: str) -> str:
    """A history.csv or events.csv column without its unit suffix ("u_1_8_m" → "u_1_8")."""
    from poundsim.results import _EVENT_FIELDS, channel_of_column
    if column in _EVENT_FIELDS:
        return _EVENT_FIELDS[column]
    try:
        return channel_of_column(column)[0]
    except KeyError:
        return column


def csv_column(path: pathlib.Path, name: str, rows=None) -> list[str]:
    """The column of a table, by its name or, in history.csv and events.csv, by its channel's."""
    header, body = read_csv(path)
    k = header.index(name) if name in header else [bare_name(h) for h in header].index(name)
    return [r[k] for r in (body if rows is None else [body[i] for i in rows])]


def png_size(path: pathlib.Path) -> tuple[int, int]:
    """(width, height) in pixels of a PNG file, which must be one and not empty."""
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert len(data) > 1000
    return struct.unpack(">II", data[16:24])


def save(fig, tmp_path, name) -> tuple[int, int]:
    path = tmp_path / f"{name}.png"
    fig.savefig(path)
    return png_size(path)


def line(ax, gid):
    found = [ln for ln in ax.get_lines() if ln.get_gid() == gid]
    assert len(found) == 1, f"{gid}: {[ln.get_gid() for ln in ax.get_lines()]}"
    return found[0]


def xy(ln):
    return np.asarray(ln.get_xdata(), dtype=float), np.asarray(ln.get_ydata(), dtype=float)


def evaluations(objective, feasible, status=None):
    """An optimisation of one variable with constraints, as evaluations.csv would hold it: one
    evaluation per objective, `feasible` 1 or 0, all `done` unless `status` says otherwise."""
    n = len(objective)
    status = status or ["done"] * n
    table = poundsim.Table({
        "evaluation": np.arange(1, n + 1), "stage": np.array(["start"] + ["global"] * (n - 1)),
        "gap_elements.damping": np.linspace(0.0, 1e7, n),
        "objective": np.array([o if s == "done" else np.nan for o, s in zip(objective, status)], dtype=float),
        "feasible": np.array(feasible, dtype=np.int64), "status": np.array(status),
        "error": np.array(["" if s == "done" else "refused" for s in status])})
    return poundsim.Optimization({"analysis": {"objective": "max_peak_drift_ratio"}}, table)


def grid_study(x_key, xs, y_key, ys, metric, values):
    """A finished grid study of one metric, `values` rows y and columns x, as study.csv holds it."""
    gx, gy = np.meshgrid(np.asarray(xs, dtype=float), np.asarray(ys, dtype=float))
    n = gx.size
    table = poundsim.Table({"id": np.arange(1, n + 1), "status": np.array(["done"] * n), x_key: gx.ravel(),
                            y_key: gy.ravel(), metric: np.asarray(values, dtype=float).ravel()})
    return poundsim.Study(table, {"analysis": {"kind": "study"}, "parameters": [x_key, y_key]})


def texts(fig) -> list[str]:
    """Every text a figure draws: titles, axis and tick labels, legends, annotations."""
    from matplotlib.text import Text

    fig.canvas.draw()  # tick labels are set when the figure is drawn (not written anywhere)
    return [t.get_text() for t in fig.findobj(Text) if t.get_text() and t.get_visible()]


def tick_labels(fig) -> list[str]:
    fig.canvas.draw()
    return [t.get_text() for a in fig.axes for t in a.get_xticklabels() + a.get_yticklabels() if t.get_text()]


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def el_centro(tmp_path_factory):
    """Four seconds of the three buildings under El Centro, every kind of channel recorded."""
    out = cli_run(EXAMPLES / "three_buildings_el_centro.toml", tmp_path_factory.mktemp("el_centro"),
                  "analysis.duration=4", f"output.channels={CHANNELS}")
    return out, poundsim.read(out)


@pytest.fixture(scope="module")
def bilinear(tmp_path_factory):
    """Three seconds of the 5- and 8-storey frames with bilinear storeys (drift_ and Fs_ recorded by
    default)."""
    out = cli_run(EXAMPLES / "el_centro_5_and_8_storeys_bilinear.toml", tmp_path_factory.mktemp("bilinear"),
                  "analysis.duration=3")
    return out, poundsim.read(out)


@pytest.fixture(scope="module")
def responses(tmp_path_factory):
    """Fig. 2c from rest and as a two-way sweep, 15 frequencies each."""
    rest = cli_run(EXAMPLES / "paper" / "fig2c.toml", tmp_path_factory.mktemp("fig2c"), "frf.points=15")
    sweep = cli_run(EXAMPLES / "paper" / "fig2c.toml", tmp_path_factory.mktemp("fig2c_sweep"), "frf.points=15",
                    "frf.sweep=both")
    return rest, poundsim.read(rest), sweep, poundsim.read(sweep)


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """The η–μ grid (5 × 4 points), each a frequency response of 9 points."""
    out = cli_run(EXAMPLES / "study_eta_mu.toml", tmp_path_factory.mktemp("study"), "frf.points=9")
    return out, poundsim.read(out)


@pytest.fixture(scope="module")
def ensemble(tmp_path_factory):
    out = cli_run(EXAMPLES / "ensemble_fig2_frames.toml", tmp_path_factory.mktemp("ensemble"))
    return out, poundsim.read(out)


@pytest.fixture(scope="module")
def optimum(tmp_path_factory):
    out = cli_run(EXAMPLES / "optimize_gap_elements.toml", tmp_path_factory.mktemp("optimize"), "frf.points=9",
                  "optimize.global_evaluations=6", "optimize.local_evaluations=4")
    return out, poundsim.read(out)


# --- Units, sizes, style ---------------------------------------------------------------------

def test_engineering_units():
    v, u = pp.to_engineering("m", [0.0, 0.012])
    assert u == "mm" and np.array_equal(v, [0.0, 12.0])
    assert pp.to_engineering("m/s2", [G])[1] == "g" and pp.to_engineering("m/s2", [G])[0][0] == 1.0
    assert pp.to_engineering("1", [0.005]) == (pytest.approx([0.5]), "%")
    assert pp.to_engineering("N", [2.5e6])[1] == "kN" and pp.to_engineering("N", [2.5e6])[0][0] == 2500.0
    assert pp.to_engineering("N", [-1.2e7])[1] == "MN" and pp.to_engineering("N", [-1.2e7])[0][0] == -12.0
    assert pp.to_engineering("N", [13.7])[1] == "N"
    assert pp.to_engineering("J", [2.4e6])[1] == "kJ" and pp.to_engineering("J", [3e7])[1] == "MJ"
    assert pp.to_engineering("m/s", [0.3])[1] == "m/s"
    assert pp.STANDARD_GRAVITY == G


def test_sizes_and_the_journal_style(el_centro, tmp_path):
    _, th = el_centro
    assert pp.COLUMN_WIDTH == 3.5 and pp.PAGE_WIDTH == 7.2 and pp.DPI == 300
    before = matplotlib.rcParams["font.size"]
    with pp.journal_style():
        assert matplotlib.rcParams["font.size"] == 8 and matplotlib.rcParams["savefig.dpi"] == 300
    assert matplotlib.rcParams["font.size"] == before
    # Saved at 300 dpi: a column is 3.5 in = 1050 px wide, a page 7.2 in = 2160 px.
    assert save(pp.time_history(th, "u_1_8"), tmp_path, "column") == (1050, 780)
    assert save(pp.time_history(th, "u_1_8", size="page"), tmp_path, "page")[0] == 2160
    assert save(pp.time_history(th, "u_1_8", size=(3.0, 2.0)), tmp_path, "tuple") == (900, 600)
    # Text drawn under the style is 8 pt.
    fig = pp.time_history(th, "u_1_8")
    assert fig.axes[0].yaxis.label.get_fontsize() == 8
    with pytest.raises(ValueError, match="'column', 'page'"):
        pp.time_history(th, "u_1_8", size="poster")


def test_the_module_imports_without_the_extension():
    code = ("import sys; sys.modules['poundsim._core'] = None; import poundsim.plot, poundsim; "
            "assert poundsim._core is None; print(poundsim.plot.__name__)")
    env = dict(os.environ, PYTHONPATH=str(SOURCE / "python"))
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "poundsim.plot"


# --- Time histories --------------------------------------------------------------------------

def test_time_history_draws_channels_in_engineering_units(el_centro, tmp_path):
    out, th = el_centro
    header, rows = read_csv(out / "history.csv")
    column = {bare_name(name): np.array([float(r[k]) for r in rows]) for k, name in enumerate(header)}
    fig = pp.time_history(th, ["u_*_8", "u_2_4"])
    ax = fig.axes[0]
    x, y = xy(line(ax, "u_1_8"))
    assert np.array_equal(x, column["t"])
    np.testing.assert_allclose(y, column["u_1_8"] * 1000, rtol=1e-15)  # mm
    np.testing.assert_allclose(xy(line(ax, "u_2_4"))[1], column["u_2_4"] * 1000, rtol=1e-15)
    assert ax.get_ylabel() == "floor displacement [mm]" and ax.get_xlabel() == "t [s]"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["8-storey frame, floor 8", "4-storey block, floor 4"]
    assert save(fig, tmp_path, "u")[0] == 1050

    # One axes per quantity, each in its unit.
    fig = pp.time_history(th, ["a_abs_1_8", "drift_ratio_1_3", "drift_1_3", "V_2", "E_input", "v_1_8", "s_1_4"])
    axes = {a.get_ylabel(): a for a in fig.axes}
    np.testing.assert_allclose(xy(line(axes["absolute floor acceleration [g]"], "a_abs_1_8"))[1],
                               column["a_abs_1_8"] / G, rtol=1e-15)
    np.testing.assert_allclose(xy(line(axes["interstorey drift ratio [%]"], "drift_ratio_1_3"))[1],
                               column["drift_ratio_1_3"] * 100, rtol=1e-15)
    np.testing.assert_allclose(xy(line(axes["interstorey drift [mm]"], "drift_1_3"))[1], column["drift_1_3"] * 1000,
                               rtol=1e-15)
    # Base shears in MN when the peak exceeds 10 MN (the 4-storey block's does, 17 MN), else kN.
    peak = np.abs(column["V_2"]).max()
    assert peak > 1e7
    np.testing.assert_allclose(xy(line(axes["base shear [MN]"], "V_2"))[1], column["V_2"] / 1e6, rtol=1e-15)
    np.testing.assert_allclose(xy(line(axes["energy [kJ]"], "E_input"))[1], column["E_input"] / 1000, rtol=1e-15)
    np.testing.assert_allclose(xy(line(axes["floor velocity [m/s]"], "v_1_8"))[1], column["v_1_8"], rtol=0)
    np.testing.assert_allclose(xy(line(axes["gap-element shortening [mm]"], "s_1_4"))[1], column["s_1_4"] * 1000,
                               rtol=1e-15)
    assert len(fig.axes) == 7
    assert [t.get_text() for t in axes["base shear [MN]"].get_legend().get_texts()] == ["4-storey block, base"]
    assert [t.get_text() for t in axes["interstorey drift ratio [%]"].get_legend().get_texts()] == \
        ["8-storey frame, storey 3"]
    save(fig, tmp_path, "quantities")

    # Into the user's axes; one quantity per axes.
    user_fig, user_ax = plt.subplots()
    assert pp.time_history(th, "u_3_2", ax=user_ax) is user_fig
    assert user_ax.get_legend().get_texts()[0].get_text() == "annex, floor 2"
    with pytest.raises(ValueError, match="draws 2 axes"):
        pp.time_history(th, ["u_3_2", "V_3"], ax=user_ax)
    with pytest.raises(KeyError, match=r"no recorded channel matches 'u_9_\*'"):
        pp.time_history(th, "u_9_*")


def test_gap_forces_in_kN_with_the_impacts_marked(el_centro, tmp_path):
    out, th = el_centro
    fig = pp.gap_forces(th)
    ax = fig.axes[0]
    forces = [c for c in th.channels if c.startswith("F_")]
    assert len(forces) == 6
    peak = max(np.abs(th[c]).max() for c in forces)
    assert 1e3 <= peak <= 1e7  # 5.2 MN: drawn in kN
    assert ax.get_ylabel() == "gap-element force [kN]"
    for c in forces:
        expected = np.array([float(v) for v in csv_column(out / "history.csv", c)]) / 1000
        np.testing.assert_allclose(xy(line(ax, c))[1], expected, rtol=1e-15)
    impacts = [float(t) for t, kind in zip(csv_column(out / "events.csv", "t"), csv_column(out / "events.csv", "kind"))
               if kind == "impact"]
    assert len(impacts) > 10
    x, y = xy(line(ax, "impacts"))
    assert np.array_equal(x, impacts) and not y.any()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"impacts ({len(impacts)})" in labels
    # Only the elements that carried a force are in the legend, named by their frames and floor.
    carried = [c for c in forces if np.any(th[c] != 0)]
    assert "8-storey frame – 4-storey block, floor 4" in labels
    assert len([lb for lb in labels if "floor" in lb]) == len(carried)
    save(fig, tmp_path, "gap_forces")


def test_hysteresis_is_storey_force_against_drift(bilinear, el_centro, tmp_path):
    out, th = bilinear
    fig = pp.hysteresis(th, 1, 1)
    ax = fig.axes[0]
    x, y = xy(line(ax, "Fs_1_1"))
    drift = np.array([float(v) for v in csv_column(out / "history.csv", "drift_1_1")])
    force = np.array([float(v) for v in csv_column(out / "history.csv", "Fs_1_1")])
    assert 1e3 <= np.abs(force).max() <= 1e7
    np.testing.assert_allclose(x, drift * 1000, rtol=1e-15)   # mm
    np.testing.assert_allclose(y, force / 1000, rtol=1e-15)   # kN
    assert ax.get_xlabel() == "interstorey drift [mm]" and ax.get_ylabel() == "storey force [kN]"
    assert ax.get_title() == "5-storey, storey 1"
    # The storey yielded; the loop reaches the summary's peak drift (taken between the output
    # instants, so a little above the sampled one).
    storey = next(fl for fl in th.summary.to_dict()["peaks"]["floors"] if fl["frame"] == 1 and fl["floor"] == 1)
    peak = storey["interstorey_drift_m"]["value"] * 1000
    assert 0.99 * peak <= np.abs(x).max() <= peak
    assert storey["storey"]["ductility"] > 1
    save(fig, tmp_path, "hysteresis")
    # Not recorded: the message names the channels= to pass.
    _, elastic = el_centro
    with pytest.raises(KeyError, match=re.escape("Fs_1_3 was not recorded: pass channels=['drift_1_*', 'Fs_1_*']")):
        pp.hysteresis(elastic, 1, 3)
    with pytest.raises(KeyError, match="no storey 9 of frame 1"):
        pp.hysteresis(elastic, 1, 9)


def test_gap_hysteresis_is_force_against_shortening(el_centro, bilinear, tmp_path):
    out, th = el_centro
    fig = pp.gap_hysteresis(th, "1_4")
    ax = fig.axes[0]
    x, y = xy(line(ax, "F_1_4"))
    np.testing.assert_allclose(x, np.array([float(v) for v in csv_column(out / "history.csv", "s_1_4")]) * 1000,
                               rtol=1e-15)
    np.testing.assert_allclose(y, np.array([float(v) for v in csv_column(out / "history.csv", "F_1_4")]) / 1000,
                               rtol=1e-15)
    assert ax.get_xlabel() == "shortening past the gap [mm]" and ax.get_ylabel() == "gap-element force [kN]"
    assert ax.get_title() == "8-storey frame – 4-storey block, floor 4"
    assert pp.gap_hysteresis(th, "F_1_4").axes[0].get_title() == ax.get_title()
    save(fig, tmp_path, "gap_hysteresis")
    with pytest.raises(KeyError, match=re.escape("s_1_2 was not recorded: pass channels=['F_1_2', 's_1_2']")):
        pp.gap_hysteresis(bilinear[1], "1_2")


def test_envelopes_are_the_summarys_peaks(el_centro, tmp_path):
    out, th = el_centro
    summary = json.loads((out / "summary.json").read_text())
    fig = pp.envelopes(th)
    disp, drift = fig.axes
    assert disp.get_xlabel() == "peak floor displacement [mm]"
    assert drift.get_xlabel() == "peak interstorey drift ratio [%]"
    for f, storeys in ((1, 8), (2, 4), (3, 2)):
        floors = sorted((fl for fl in summary["peaks"]["floors"] if fl["frame"] == f), key=lambda fl: fl["floor"])
        assert len(floors) == storeys
        x, y = xy(line(disp, f"u_{f}"))
        assert np.array_equal(y, np.arange(1, storeys + 1))
        np.testing.assert_allclose(x, [fl["displacement_m"]["value"] * 1000 for fl in floors], rtol=1e-15)
        np.testing.assert_allclose(xy(line(disp, f"u_{f}_free"))[0],
                                   [fl["free"]["displacement_m"] * 1000 for fl in floors], rtol=1e-15)
        np.testing.assert_allclose(xy(line(drift, f"drift_{f}"))[0],
                                   [fl["interstorey_drift_ratio"] * 100 for fl in floors], rtol=1e-15)
        np.testing.assert_allclose(xy(line(drift, f"drift_{f}_free"))[0],
                                   [fl["free"]["interstorey_drift_ratio"] * 100 for fl in floors], rtol=1e-15)
        assert line(disp, f"u_{f}").get_linestyle() == "-" and line(disp, f"u_{f}_free").get_linestyle() == "--"
    assert "8-storey frame, pounding" in [t.get_text() for t in disp.get_legend().get_texts()]
    assert save(fig, tmp_path, "envelopes")[0] == 2160
    # Into a pair of the user's axes.
    user_fig, pair = plt.subplots(1, 2)
    assert pp.envelopes(th, ax=pair) is user_fig


def test_energy_balance_in_kJ(bilinear, tmp_path):
    out, th = bilinear
    fig = pp.energy(th)
    ax = fig.axes[0]
    e_input = np.array([float(v) for v in csv_column(out / "history.csv", "E_input")])
    assert 1e3 <= e_input.max() <= 1e7
    np.testing.assert_allclose(xy(line(ax, "E_input"))[1], e_input / 1000, rtol=1e-15)
    assert ax.get_ylabel() == "energy [kJ]"
    stack = ["E_kinetic", "E_storey_strain", "E_gap_strain", "E_storey_hysteretic", "E_storey_damping",
             "E_gap_damping", "E_impact"]
    assert len(ax.collections) == len(stack)
    # The top of the stack is the sum of the terms (the input less the residual).
    total = sum(np.array([float(v) for v in csv_column(out / "history.csv", c)]) for c in stack) / 1000
    top = ax.collections[-1].get_paths()[0].vertices[:, 1]
    assert top.max() == pytest.approx(total.max(), rel=1e-12)
    assert total.max() == pytest.approx(e_input.max() / 1000, rel=1e-5)
    assert "storey hysteresis" in [t.get_text() for t in ax.get_legend().get_texts()]
    save(fig, tmp_path, "energy")


# --- Frequency responses ---------------------------------------------------------------------

def test_frf_is_the_tables_columns(responses, tmp_path):
    rest_dir, rest, sweep_dir, sweep = responses
    fig = pp.frf(rest, sweep=sweep)
    ax = fig.axes[0]
    ratio = np.array([float(v) for v in csv_column(rest_dir / "frf.csv", "ratio")])
    order = np.argsort(ratio)
    for f in (1, 2):
        x, y = xy(line(ax, f"V{f}_W"))
        assert np.array_equal(x, ratio[order])
        assert np.array_equal(y, np.array([float(v) for v in csv_column(rest_dir / "frf.csv", f"V{f}_W")])[order])
        x, y = xy(line(ax, f"V{f}_free_W"))
        assert np.array_equal(y, np.array([float(v) for v in csv_column(rest_dir / "frf.csv", f"V{f}_free_W")])[order])
        assert line(ax, f"V{f}_W").get_linestyle() == "-" and line(ax, f"V{f}_free_W").get_linestyle() == "--"
        assert line(ax, f"V{f}_W").get_color() == ("tab:blue" if f == 1 else "tab:red")
        # The sweep's branches as markers ▲ ▼, each its rows of the sweep's table.
        branch = csv_column(sweep_dir / "frf.csv", "branch")
        for name, marker in (("up", "^"), ("down", "v")):
            rows = [i for i, b in enumerate(branch) if b == name]
            assert len(rows) == 15
            x, y = xy(line(ax, f"V{f}_W_{name}"))
            expected_x = np.array([float(v) for v in csv_column(sweep_dir / "frf.csv", "ratio", rows)])
            expected_y = np.array([float(v) for v in csv_column(sweep_dir / "frf.csv", f"V{f}_W", rows)])
            o = np.argsort(expected_x, kind="stable")
            assert np.array_equal(x, expected_x[o]) and np.array_equal(y, expected_y[o])
            assert line(ax, f"V{f}_W_{name}").get_marker() == marker
    assert ax.get_xlabel() == "ω̄ / ω₁" and ax.get_ylabel() == "V / W"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[:2] == ["frame 1, interacting", "frame 1, free"] and "sweep up" in labels
    save(fig, tmp_path, "frf")
    # A sweep alone: markers, and the free curves once per frequency; free=False leaves them out.
    fig = pp.frf(sweep)
    assert len(xy(line(fig.axes[0], "V1_free_W"))[0]) == 15
    assert not [ln for ln in pp.frf(rest, free=False).axes[0].get_lines() if "free" in str(ln.get_gid())]
    save(fig, tmp_path, "sweep")


# --- Studies, ensembles, optimisations -------------------------------------------------------

def test_study_map_is_the_metric_on_the_grid(study, tmp_path):
    out, result = study
    header, rows = read_csv(out / "study.csv")
    k = {name: i for i, name in enumerate(header)}
    etas = sorted({float(r[k["model.dimensionless.eta"]]) for r in rows})
    mus = sorted({float(r[k["model.dimensionless.mu"]]) for r in rows})
    expected = np.full((len(mus), len(etas)), np.nan)
    for r in rows:
        eta, mu = float(r[k["model.dimensionless.eta"]]), float(r[k["model.dimensionless.mu"]])
        expected[mus.index(mu), etas.index(eta)] = float(r[k["max_ratio_to_bare"]])
    assert expected.shape == (4, 5) and np.isfinite(expected).all()
    fig = pp.study_map(result, "model.dimensionless.eta", "model.dimensionless.mu", "max_ratio_to_bare")
    ax, colorbar = fig.axes
    grid = np.asarray(ax.collections[0].get_array()).reshape(expected.shape)
    assert np.array_equal(grid, expected)
    assert colorbar.get_ylabel() == "peak V/W ÷ bare pounding's, worse frame"
    assert [t.get_text() for t in ax.get_xticklabels()] == [f"{v:g}" for v in etas]
    assert ax.get_xlabel() == "η = k / K₁"
    # The lowest cell is outlined, and its value printed among the cells'.
    j, i = np.unravel_index(np.argmin(expected), expected.shape)
    lowest = next(p for p in ax.patches if p.get_gid() == "lowest")
    assert lowest.get_xy() == (i - 0.5, j - 0.5)
    assert f"{expected.min():.3g}" in [t.get_text() for t in ax.texts]
    save(fig, tmp_path, "study")
    # On the parameters' values; fixed to one μ; not one point per cell.
    fig = pp.study_map(result, "model.dimensionless.eta", "model.dimensionless.mu", "max_ratio_to_bare",
                       spacing="value")
    assert np.array_equal(np.asarray(fig.axes[0].collections[0].get_array()).reshape(expected.shape), expected)
    save(fig, tmp_path, "study_values")
    fig = pp.study_map(result, "model.dimensionless.eta", "model.dimensionless.mu", "peak_V1_W",
                       fix={"model.dimensionless.mu": 1.0})
    row = [float(r[k["peak_V1_W"]]) for r in sorted(rows, key=lambda r: float(r[k["model.dimensionless.eta"]]))
           if float(r[k["model.dimensionless.mu"]]) == 1.0]
    assert np.array_equal(np.asarray(fig.axes[0].collections[0].get_array()).ravel(), row)
    with pytest.raises(ValueError, match="several points at"):
        pp.study_map(result, "model.dimensionless.eta", "model.dimensionless.eta", "max_ratio_to_bare")
    with pytest.raises(ValueError, match="no column 'peak'"):
        pp.study_map(result, "model.dimensionless.eta", "model.dimensionless.mu", "peak")


def test_a_study_map_of_drift_ratios_reads_in_percent_with_named_axes():
    damping, eta = [1e6, 10 ** 6.5, 1e7], [0.0625, 0.125, 0.25]
    drift = np.array([[0.0123, 0.0118, 0.0131], [0.0109, 0.0104, 0.0127], [0.0146, 0.0099, 0.0112]])
    study = grid_study("gap_elements.damping", damping, "model.dimensionless.eta", eta, "max_peak_drift_ratio", drift)
    for spacing in ("even", "value"):
        fig = pp.study_map(study, "gap_elements.damping", "model.dimensionless.eta", "max_peak_drift_ratio",
                           spacing=spacing)
        ax, colorbar = fig.axes
        np.testing.assert_allclose(np.asarray(ax.collections[0].get_array()).reshape(drift.shape), drift * 100,
                                   rtol=1e-15)
        # Three significant digits of the % (every cell was "0.01").
        cells = [t.get_text() for t in ax.texts]
        assert sorted(cells) == sorted(f"{v:.3g}" for v in (drift * 100).ravel()) and "1.23" in cells
        assert colorbar.get_ylabel() == "peak drift ratio, worse frame [%]"
        assert ax.get_xlabel() == "gap-element damping c [N·s/m]" and ax.get_ylabel() == "η = k / K₁"
        for label in (ax.get_xlabel(), ax.get_ylabel(), colorbar.get_ylabel()):
            assert "_" not in label and "dimensionless" not in label
        labels = tick_labels(fig)
        assert labels and not [t for t in labels if re.search(r"e[+-]0|\d{5}", t)], labels
        assert [t.get_text() for t in ax.get_xticklabels()] == ["1e6", "3.16e6", "1e7"]
        assert ax.get_xscale() == ("log" if spacing == "value" else "linear")
    # Ratios that are no drifts stay as they are; larger values keep three digits, without an exponent.
    fig = pp.study_map(grid_study("a", [1, 2], "b", [1, 2], "max_ratio_to_free", [[0.4666, 1.0], [12.345, 123.4]]),
                       "a", "b", "max_ratio_to_free")
    assert sorted(t.get_text() for t in fig.axes[0].texts) == ["0.467", "1", "12.3", "123"]
    assert fig.axes[1].get_ylabel() == "peak V/W ÷ free frame's, worse frame"


def test_ensemble_amplification_per_record_and_mean(ensemble, tmp_path):
    out, result = ensemble
    summary = json.loads((out / "summary.json").read_text())
    header, rows = read_csv(out / "ensemble.csv")
    k = {name: i for i, name in enumerate(header)}
    assert len(rows) == 4
    fig = pp.ensemble_amplification(result)
    ax = fig.axes[0]
    bars = list(ax.containers[0])
    np.testing.assert_allclose([b.get_height() for b in bars],
                               [summary["mean"]["ratio_to_free_1"], summary["mean"]["ratio_to_free_2"]], rtol=1e-12)
    for n, r in enumerate(rows):
        y = xy(line(ax, f"record_{n}"))[1]
        assert np.array_equal(y, [float(r[k["ratio_to_free_1"]]), float(r[k["ratio_to_free_2"]])])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[:4] == [os.path.splitext(os.path.basename(r[k["excitation.file"]]))[0] for r in rows]
    assert ax.get_ylabel() == "peak base shear: pounding ÷ free"
    save(fig, tmp_path, "ensemble")
    fig = pp.ensemble_floor_amplification(result)
    ax = fig.axes[0]
    for prefix in ("amp_u", "amp_drift", "amp_acc"):
        y = xy(line(ax, f"{prefix}_largest"))[1]
        np.testing.assert_allclose(y, [summary["max"][f"{prefix}_1_1"], summary["max"][f"{prefix}_2_1"]], rtol=1e-12)
    heights = [[b.get_height() for b in c] for c in ax.containers]  # displacement, drift, acceleration
    assert [c.get_label() for c in ax.containers] == ["displacement", "interstorey drift", "absolute acceleration"]
    np.testing.assert_allclose(heights[0], [summary["mean"]["amp_u_1_1"], summary["mean"]["amp_u_2_1"]], rtol=1e-12)
    np.testing.assert_allclose(heights[2], [summary["mean"]["amp_acc_1_1"], summary["mean"]["amp_acc_2_1"]],
                               rtol=1e-12)
    save(fig, tmp_path, "ensemble_floors")


def test_optimization_against_bare_pounding(optimum, tmp_path):
    out, result = optimum
    fig = pp.optimization(result)
    ax = fig.axes[0]
    for name, gid in (("optimum_frf", "V{}_W"), ("bare_frf", "V{}_W_compare")):
        ratio = np.array([float(v) for v in csv_column(out / f"{name}.csv", "ratio")])
        for f in (1, 2):
            x, y = xy(line(ax, gid.format(f)))
            assert np.array_equal(x, ratio)
            assert np.array_equal(y, [float(v) for v in csv_column(out / f"{name}.csv", f"V{f}_W")])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "frame 1, optimum" in labels and "frame 2, bare pounding" in labels
    save(fig, tmp_path, "optimum")
    # Without frequency responses: the objective per evaluation, the optimum starred.
    summary = json.loads((out / "optimize.json").read_text())
    without = poundsim.Optimization(summary, result.evaluations)
    fig = pp.optimization(without)
    ax = fig.axes[0]
    objective = [float(v) for v in csv_column(out / "evaluations.csv", "objective")]
    stage = csv_column(out / "evaluations.csv", "stage")
    assert np.array_equal(xy(line(ax, "stage_global"))[1], [o for o, s in zip(objective, stage) if s == "global"])
    assert xy(line(ax, "optimum"))[1][0] == summary["objective"] == min(objective)
    assert xy(line(ax, "best"))[1][-1] == min(objective)
    assert ax.get_ylabel() == "peak V/W, worse frame"
    save(fig, tmp_path, "evaluations")


def test_the_optimum_and_the_best_so_far_are_of_feasible_evaluations():
    # The lowest objectives break a constraint (evaluations 2 and 4); the input refused the 7th.
    objective = [0.020, 0.012, 0.018, 0.009, 0.015, 0.011, 0.0]
    opt = evaluations(objective, [0, 0, 1, 0, 1, 1, 0], status=["done"] * 6 + ["rejected"])
    ax = pp.optimization(opt).axes[0]
    percent = np.array(objective) * 100  # a drift ratio, drawn in %
    assert ax.get_ylabel() == "peak drift ratio, worse frame [%]"
    x, y = xy(line(ax, "optimum"))
    assert (x.tolist(), y.tolist()) == ([6.0], [percent[5]])
    # The best so far starts at the first feasible evaluation and holds feasible values only.
    x, y = xy(line(ax, "best"))
    assert x.tolist() == [3, 4, 5, 6, 7] and y.tolist() == percent[[2, 2, 4, 5, 5]].tolist()
    assert not set(y.tolist()) & set(percent[[0, 1, 3]].tolist())
    # The infeasible ones apart, grey, labelled; the feasible ones by stage.
    infeasible = line(ax, "infeasible")
    assert xy(infeasible)[0].tolist() == [1, 2, 4] and xy(infeasible)[1].tolist() == percent[[0, 1, 3]].tolist()
    assert infeasible.get_label() == "infeasible" and infeasible.get_color() == "0.6"
    assert infeasible.get_marker() != line(ax, "stage_global").get_marker()
    assert xy(line(ax, "stage_global"))[0].tolist() == [3, 5, 6]
    assert "stage_start" not in [ln.get_gid() for ln in ax.get_lines()]  # its one evaluation is infeasible
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"infeasible", "best so far", "optimum"} <= set(labels)
    # None feasible: no optimum and no best so far, and the legend says why.
    ax = pp.optimization(evaluations([0.02, 0.01, 0.015], [0, 0, 0])).axes[0]
    gids = [ln.get_gid() for ln in ax.get_lines()]
    assert "optimum" not in gids and "best" not in gids and "infeasible" in gids
    assert ax.get_legend().get_title().get_text() == "no feasible evaluation: no optimum"


def test_compare_runs_from_the_summaries(el_centro, bilinear, tmp_path):
    ths = [el_centro[1], bilinear[1]]
    fig = pp.compare_runs(ths, labels=["three", "two"])
    force, shear, dissipated = fig.axes
    summaries = [th.summary.to_dict() for th in ths]
    np.testing.assert_allclose([b.get_height() for b in force.patches],
                               [s["max_gap_force_N"] / 1000 for s in summaries], rtol=1e-15)
    assert force.get_ylabel() == "peak gap-element force [kN]"
    np.testing.assert_allclose([b.get_height() for b in shear.containers[0]],
                               [s["peaks"]["base_shear"][0]["over_frame1_weight"] for s in summaries], rtol=1e-15)
    lost = [(s["energy"]["gap_damping_J"] + s["energy"]["impact_loss_J"]) / 1000 for s in summaries]
    np.testing.assert_allclose([b.get_height() for b in dissipated.patches], lost, rtol=1e-15)
    assert dissipated.get_ylabel() == "dissipated by the gap elements [kJ]"
    save(fig, tmp_path, "compare")


# --- poundsim.read's tables --------------------------------------------------------------------

def check_table(table: poundsim.Table, path: pathlib.Path, expected_types: dict):
    """Every column against the CSV's text: whole numbers int64, numbers float64 (an empty field
    NaN), any other text str; and the named columns of the named types."""
    header, rows = read_csv(path)
    assert table.names == header and len(table) == len(rows)
    for k, name in enumerate(header):
        text = [r[k] for r in rows]
        values = table[name]
        if values.dtype == np.int64:
            assert all(re.fullmatch(r"-?\d+", t) for t in text), name
            assert values.tolist() == [int(t) for t in text], name
        elif values.dtype == np.float64:
            expected = np.array([float(t) if t else np.nan for t in text])
            assert np.array_equal(values, expected, equal_nan=True), name
        else:
            assert values.dtype.kind == "U", (name, values.dtype)
            assert values.tolist() == text, name
    for name, dtype in expected_types.items():
        assert table[name].dtype == dtype or (dtype is str and table[name].dtype.kind == "U"), (name, table[name].dtype)


def test_read_gives_the_csv_tables_typed(responses, study, ensemble, optimum, el_centro):
    rest_dir, rest, _, _ = responses
    check_table(rest.table, rest_dir / "frf.csv", {"ratio": np.float64, "V1_W": np.float64, "periodicity": np.int64,
                                                   "branch": str, "events": np.int64})
    assert set(rest["branch"].tolist()) == {"rest"}
    out, s = study
    check_table(s.table, out / "study.csv", {"id": np.int64, "status": str, "model.dimensionless.mu": np.float64,
                                             "max_ratio_to_bare": np.float64, "points": np.int64})
    assert s.parameters == ["model.dimensionless.eta", "model.dimensionless.mu"] and s.kind == "study"
    assert s.database == os.path.join(str(out), "study.sqlite")
    out, e = ensemble
    check_table(e.table, out / "ensemble.csv", {"id": np.int64, "excitation.file": str, "amp_u_1_1": np.float64})
    assert e.kind == "ensemble"
    out, o = optimum
    check_table(o.evaluations, out / "evaluations.csv", {"evaluation": np.int64, "stage": str, "objective": np.float64})
    check_table(o.optimum_frf, out / "optimum_frf.csv", {"V2_free_W": np.float64})
    assert o.optimum == json.loads((out / "optimize.json").read_text())["optimum"]
    out, th = el_centro
    events = poundsim.Table.read_csv(out / "events.csv")
    check_table(events, out / "events.csv", {"t_s": np.float64, "floor": np.int64, "kind": str})
    assert np.array_equal(th.events["t"], events["t_s"]) and th.events["kind"].tolist() == events["kind"].tolist()


# --- The scripts ---------------------------------------------------------------------------------

def script(name: str, *args) -> subprocess.CompletedProcess:
    r = subprocess.run([sys.executable, str(SCRIPTS / name), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    return r


def test_a_pareto_front_is_drawn_as_written(tmp_path):
    out = cli_run(EXAMPLES / "design_5_and_8_storeys.toml", tmp_path / "design", "analysis.duration=2",
                  "optimize.global_evaluations=4", "optimize.local_evaluations=4", "optimize.pareto.points=3")
    opt = poundsim.read(out)
    fig = pp.pareto(opt, reference={"bare pounding": (0.02, 0.01)})
    ax = fig.axes[0]
    front = next(line for line in ax.lines if line.get_gid() == "front")
    keep = (np.asarray(opt.pareto["dominated"]) == 0) & (np.asarray(opt.pareto["feasible"]) == 1)
    x = np.asarray(opt.pareto["peak_drift_ratio_2"])[keep] * 100  # drift ratios in %
    order = np.argsort(x)
    assert np.array_equal(front.get_xdata(), x[order])
    assert np.array_equal(front.get_ydata(), (np.asarray(opt.pareto["peak_drift_ratio_1"])[keep] * 100)[order])
    assert ax.get_xlabel() == "peak drift ratio, frame 2 [%]" and ax.get_ylabel() == "peak drift ratio, frame 1 [%]"
    assert [v.tolist() for v in xy(line(ax, "reference_0"))] == [[2.0], [1.0]]
    plt.close(fig)
    script("plot_pareto.py", out)
    png_size(out / "pareto.png")
    # Its evaluations: the optimum marked is the best feasible one, optimize.json's.
    ax = pp.optimization(opt).axes[0]
    ev = opt.evaluations
    feasible = np.flatnonzero((np.asarray(ev["feasible"]) == 1) & (np.asarray(ev["status"]) == "done"))
    best = feasible[np.argmin(ev["objective"][feasible])]
    x, y = xy(line(ax, "optimum"))
    assert x[0] == ev["evaluation"][best] and y[0] == ev["objective"][best] * 100
    assert ev["objective"][best] == opt.summary.objective
    assert opt.summary.feasible
    assert not set(xy(line(ax, "best"))[1]) & set(ev["objective"][np.asarray(ev["feasible"]) == 0] * 100)
    with pytest.raises(ValueError, match="no Pareto front"):
        pp.pareto(poundsim.Optimization({}, opt.evaluations))


def test_a_scaled_ensembles_spectra_are_drawn_as_written(tmp_path):
    out = cli_run(EXAMPLES / "ensemble_ec8_spectrum.toml", tmp_path / "scaled")
    result = poundsim.read(out)
    t = result.spectra
    fig = pp.spectra(result)
    ax = fig.axes[0]
    for i in range(1, 5):
        x, y = xy(line(ax, f"record_{i}"))
        assert np.array_equal(x, t["period_s"]) and np.array_equal(y, t[f"sa_{i}_g"])
    assert np.array_equal(xy(line(ax, "mean"))[1], t["mean_g"])
    assert np.array_equal(xy(line(ax, "target"))[1], t["target_g"])
    assert line(ax, "target").get_linestyle() == "--"
    lo, hi = result.summary.to_dict()["scaling"]["range_s"]
    span = next(p for p in ax.patches if p.get_gid() == "range")
    np.testing.assert_allclose(sorted({v[0] for v in span.get_xy()}), [lo, hi], rtol=1e-15)
    assert ax.get_xscale() == "log"
    assert "EN 1998-1 type 1" in [x.get_text() for x in ax.get_legend().get_texts()]
    save(fig, tmp_path, "spectra")
    with pytest.raises(ValueError, match="no spectra"):
        pp.spectra(poundsim.read(cli_run(EXAMPLES / "ensemble_fig2_frames.toml", tmp_path / "plain")))


def test_the_scripts_draw_through_the_module(el_centro, bilinear, responses, study, ensemble, optimum, tmp_path):
    rest_dir, _, sweep_dir, _ = responses
    script("plot_frf.py", "--figure", rest_dir / "frf.csv", tmp_path / "fig.png", sweep_dir / "frf.csv", "Fig. 2c",
           "--figure", rest_dir / "frf.csv", tmp_path / "alone.png", "-", "alone")
    png_size(tmp_path / "fig.png")
    png_size(tmp_path / "alone.png")
    out, _ = optimum
    script("plot_frf.py", out / "optimum_frf.csv", tmp_path / "optimum.png", "--compare", out / "bare_frf.csv",
           "bare pounding")
    png_size(tmp_path / "optimum.png")
    out, _ = study
    script("plot_study.py", out / "study.sqlite", "model.dimensionless.eta", "model.dimensionless.mu",
           "max_ratio_to_bare", tmp_path / "map.png")
    png_size(tmp_path / "map.png")
    bad = subprocess.run([sys.executable, str(SCRIPTS / "plot_study.py"), str(out / "study.sqlite"), "eta", "mu",
                          "max_ratio_to_bare", str(tmp_path / "no.png")], capture_output=True, text=True)
    assert bad.returncode == 1 and "the points do not vary eta and mu" in bad.stderr
    assert not (tmp_path / "no.png").exists()
    out, _ = ensemble
    script("plot_ensemble.py", out)
    png_size(out / "amplification.png")
    scaled = cli_run(EXAMPLES / "ensemble_ec8_spectrum.toml", tmp_path / "scaled")
    script("plot_spectra.py", scaled)
    png_size(scaled / "spectra.png")
    out, _ = el_centro
    script("plot_time_history.py", out)
    for name in ("response", "energy", "profiles"):
        assert png_size(out / f"{name}.png")[0] == 2160
    r = script("compare_contact_laws.py", out, bilinear[0], "--out", tmp_path / "laws.png")
    force = el_centro[1].summary.max_gap_force_N
    assert f"| paper | {force:.4g} | " in r.stdout and "| hertzdamp | " in r.stdout
    png_size(tmp_path / "laws.png")


def drawn(monkeypatch, name: str, *args) -> list:
    """The figures a script saves, run in this process: their artists, to read what they show
    (the files are written as well)."""
    import matplotlib.figure

    figures = []
    savefig = matplotlib.figure.Figure.savefig

    def keep(fig, *a, **k):
        figures.append(fig)
        return savefig(fig, *a, **k)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", keep)
    monkeypatch.setattr(sys, "argv", [str(SCRIPTS / name), *map(str, args)])
    monkeypatch.syspath_prepend(str(SCRIPTS))
    runpy.run_path(str(SCRIPTS / name), run_name="__main__")
    return figures


def test_the_study_script_labels_its_map(study, tmp_path, monkeypatch):
    out, result = study
    figures = drawn(monkeypatch, "plot_study.py", out / "study.sqlite", "model.dimensionless.eta",
                    "model.dimensionless.mu", "max_ratio_to_bare", tmp_path / "map.png")
    assert len(figures) == 1
    ax, colorbar = figures[0].axes
    assert sorted(t.get_text() for t in ax.texts) == sorted(f"{v:.3g}" for v in result["max_ratio_to_bare"])
    shown = texts(figures[0])
    assert not [t for t in shown if "_" in t or "dimensionless" in t], shown
    assert ax.get_title() == "peak V/W ÷ bare pounding's, worse frame"


def test_a_missing_panel_is_left_out_not_drawn_as_its_error(tmp_path, monkeypatch, capsys):
    # Displacements alone: no gap-element forces for response.png's lower panel, no energy.png.
    out = cli_run(EXAMPLES / "fig2c_ratio0.8.toml", tmp_path / "u", "analysis.duration=0.5",
                  'output.channels=["u_*"]')
    figures = drawn(monkeypatch, "plot_time_history.py", out)
    err = capsys.readouterr().err
    assert "energy.png not written: the energy channels were not recorded" in err
    assert "response.png: no gap-element force was recorded" in err
    assert not (out / "energy.png").exists() and (out / "response.png").exists() and (out / "profiles.png").exists()
    assert len(figures) == 2
    for fig in figures:
        shown = texts(fig)
        assert not [t for t in shown if "recorded" in t or "channels" in t or "no " in t], shown
    response = figures[0]
    assert len(response.axes) == 1 and [ln.get_gid() for ln in response.axes[0].get_lines()] == ["u_1_1", "u_2_1"]


def assert_stretches_are_branch_rows(ax, t, x: str):
    """Each drawn stretch of a continuation is its branch's rows against column `x`, in arclength
    order, of its stability (solid stable, dashed unstable), but for the one point a stretch shares
    with the next."""
    branch_id, stable = np.asarray(t["branch_id"]), np.asarray(t["stable"]) == 1
    drawn = {ln.get_gid(): ln for ln in ax.get_lines() if ln.get_gid()}
    assert any(g.endswith("_unstable") for g in drawn) and any(g.endswith("_stable") for g in drawn)
    for gid, ln in drawn.items():
        m = re.fullmatch(r"V(\d)_W_branch(\d+)_(stable|unstable)", gid)
        if not m:
            continue
        f, b, kind = int(m.group(1)), int(m.group(2)), m.group(3)
        assert ln.get_linestyle() == ("-" if kind == "stable" else "--")
        xs, ys = xy(ln)
        rows = np.flatnonzero(branch_id == b)
        matches = [int(np.flatnonzero((t[x][rows] == xi) & (t[f"V{f}_W"][rows] == yi))[0]) for xi, yi in zip(xs, ys)]
        assert all(stable[rows[i]] == (kind == "stable") for i in matches[:-1])
        assert matches == list(range(matches[0], matches[0] + len(matches)))


def test_frf_by_continuation_draws_stable_solid_and_unstable_dashed(tmp_path):
    # Fig. 2b between 0.55 and 0.8 by continuation: the resonance branch folds over an unstable
    # stretch; each stretch is the table's rows of that branch and stability, in arclength order.
    out = cli_run(EXAMPLES / "paper" / "fig2b.toml", tmp_path / "continued", "frf.points=26", "frf.ratio_min=0.55",
                  "frf.ratio_max=0.8", 'frf.method="continuation"', 'analysis.integrator="exact"',
                  "frf.steps_per_period=32")
    fr = poundsim.read(out)
    t = fr.table
    fig = pp.frf(fr)
    ax = fig.axes[0]
    assert_stretches_are_branch_rows(ax, t, "ratio")
    folds = np.flatnonzero(np.asarray(t["bifurcation"]).astype(str) == "fold")
    assert len(folds) >= 1
    x, y = xy(line(ax, "V1_W_fold"))
    assert np.array_equal(x, t["ratio"][folds]) and np.array_equal(y, t["V1_W"][folds])
    labels = [tx.get_text() for tx in ax.get_legend().get_texts()]
    assert "frame 1, unstable" in labels and "fold" in labels
    # The free frames are dotted, told apart from the dashed unstable branches.
    assert line(ax, "V1_free_W").get_linestyle() == ":" and line(ax, "V2_free_W").get_linestyle() == ":"
    save(fig, tmp_path, "frf_continuation")


def test_a_continuation_in_a_parameter_is_drawn_against_it(tmp_path):
    # Fig. 2c's frames at 0.8 ω₁ as the gap opens (examples/continuation): each drawn stretch is
    # its branch's rows in arclength order against the parameter, stable solid, unstable dashed,
    # its Neimark–Sacker points marked, the free frames dotted, the x axis named δ̄.
    out = cli_run(EXAMPLES / "continuation" / "fig2c_gap.toml", tmp_path / "gap", "parameter.max=1.2")
    c = poundsim.read(out)
    t = c.table
    fig = pp.continuation(c)
    ax = fig.axes[0]
    assert_stretches_are_branch_rows(ax, t, "parameter")
    ns = np.flatnonzero(np.asarray(t["bifurcation"]).astype(str) == "Neimark-Sacker")
    assert len(ns) == 2
    x, _ = xy(line(ax, "V1_W_Neimark-Sacker"))
    assert np.array_equal(x, t["parameter"][ns])
    assert line(ax, "V1_free_W").get_linestyle() == ":"
    assert ax.get_xlabel() == "δ̄ = δλ² / g"
    assert ax.get_xlim() == (0.05, 1.2)
    save(fig, tmp_path, "continuation")
    script("plot_continuation.py", out, tmp_path / "script.png", "--title", "gap")
    png_size(tmp_path / "script.png")
