"""poundsim's Python module against the command line: the same input gives the same numbers, bit
for bit; channels, events and summaries as arrays and objects; errors, progress, Ctrl-C and the GIL
as a Python user expects them (docs/python.md)."""

import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import poundsim

from support import EXAMPLES, cli_run, read_csv


@pytest.fixture(scope="module")
def el_centro(tmp_path_factory):
    """The three buildings under El Centro, by the command line and by Python."""
    model = EXAMPLES / "three_buildings_el_centro.toml"
    out = cli_run(model, tmp_path_factory.mktemp("cli"))
    return model, out, poundsim.run(poundsim.load(model), progress=False)


def test_the_history_is_the_command_lines_bit_for_bit(el_centro):
    _, out, th = el_centro
    header, rows = read_csv(out / "history.csv")
    # Each column is its channel with the unit as a suffix (u_1_1_m, v_1_1_m_s, drift_ratio_1_1 bare).
    from poundsim.results import channel_of_column
    assert [channel_of_column(h) for h in header] == [("t", "s")] + list(zip(th.channels, th.units))
    assert header[0] == "t_s" and "u_1_1_m" in header and "E_input_J" in header
    # The CSV holds each double's shortest exact form: read back, it is the same double.
    expected = np.array([[float(x) for x in row] for row in rows])
    assert th.data.shape == expected.shape
    assert np.array_equal(th.data, expected)
    assert th.units[th.channels.index("u_1_1")] == "m"
    assert th.unit("F_2_2") == "N" and th.unit("E_input") == "J"


def test_events_are_events_csv(el_centro):
    _, out, th = el_centro
    header, rows = read_csv(out / "events.csv")
    assert len(th.events) == len(rows) > 0
    assert th.events.dtype.names == (
        "t", "frame_left", "frame_right", "floor", "right_floor", "kind",
        "relative_velocity_before", "relative_velocity_after", "impulse")
    for event, row in zip(th.events, rows):
        record = dict(zip(header, row))
        assert event["t"] == float(record["t_s"])
        assert event["kind"] == record["kind"]
        assert event["floor"] == int(record["floor"])
        assert event["impulse"] == float(record["impulse_Ns"])


def test_the_summary_is_summary_json(el_centro):
    _, out, th = el_centro
    expected = json.loads((out / "summary.json").read_text())
    got = th.summary.to_dict()
    expected.pop("run_time_s", None)
    got.pop("run_time_s", None)
    assert got == expected
    assert th.summary.energy.input_J == expected["energy"]["input_J"]
    assert th.summary.peaks.base_shear[0].value_N == expected["peaks"]["base_shear"][0]["value_N"]
    with pytest.raises(AttributeError, match="the summary has no 'energie'"):
        th.summary.energie


def test_arrays_are_views_of_one_buffer(el_centro):
    _, _, th = el_centro
    assert not th.data.flags.owndata  # the run's buffer, handed over without a copy
    assert np.shares_memory(th.values, th.data) and np.shares_memory(th.time, th.data)
    assert np.shares_memory(th["u_1_8"], th.data)
    assert th.time[0] == 0.0 and th.time[-1] == th.summary.analysis.duration_s
    frame = th.to_pandas()
    assert frame.shape == (th.data.shape[0], len(th.channels))
    assert frame.index.name == "t" and list(frame.columns) == th.channels
    with pytest.raises(KeyError, match="no channel 'u_9_9' was recorded"):
        th["u_9_9"]


def test_channels_choose_quantities_frames_and_floors():
    model = poundsim.load(EXAMPLES / "three_buildings_el_centro.toml", settings=["analysis.duration=5.0"])
    th = poundsim.run(model, channels=["drift_2_*", "u_2_*", "a_abs_3_?"], progress=False)
    assert th.channels == ["u_2_1", "u_2_2", "u_2_3", "u_2_4", "a_abs_3_1", "a_abs_3_2",
                           "drift_2_1", "drift_2_2", "drift_2_3", "drift_2_4"]
    # A drift is the difference of its floors' displacements, to the bit.
    assert np.array_equal(th["drift_2_1"], th["u_2_1"])
    assert np.array_equal(th["drift_2_3"], th["u_2_3"] - th["u_2_2"])
    # The absolute acceleration is the relative one plus the ground's.
    both = poundsim.run(model, channels=["a_3_1", "a_abs_3_1"], progress=False)
    ground = both["a_abs_3_1"] - both["a_3_1"]
    assert np.ptp(ground) > 1.0  # El Centro at 0.5 g
    assert np.array_equal(both["a_abs_3_1"], th["a_abs_3_1"])


def test_bad_input_raises_value_error_with_the_command_lines_message(tmp_path):
    text = (EXAMPLES / "fig2c_ratio0.8.toml").read_text().replace("dt = ", "dt = -", 1)
    with pytest.raises(ValueError, match=r"bad\.toml:\d+:\d+: analysis\.dt: must be > 0"):
        poundsim.loads(text, name="bad.toml")
    with pytest.raises(poundsim.InputError):
        poundsim.load(EXAMPLES / "fig2c_ratio0.8.toml", settings=["analysis.dtt=0.1"])
    model = poundsim.load(EXAMPLES / "fig2c_ratio0.8.toml")
    with pytest.raises(ValueError, match=r'output\.channels: "s_9_\*" names no channel'):
        poundsim.run(model, channels=["u_*", "s_9_*"], progress=False)
    frf = poundsim.load(EXAMPLES / "paper" / "fig2c.toml")
    with pytest.raises(ValueError, match="channels are for time histories"):
        poundsim.run(frf, channels=["u_*"])
    with pytest.raises(ValueError, match='analysis.kind: "frf" is not a time history'):
        poundsim._core.run_time_history(frf)


def test_inputs_are_the_command_lines_toml():
    model = poundsim.load(EXAMPLES / "fig2c_ratio0.8.toml")
    again = poundsim.loads(model.to_toml(), name="input.toml")
    assert again.to_toml() == model.to_toml()
    shorter = model.with_settings(["analysis.duration=2.0"])
    assert shorter.duration == 2.0 and model.duration != 2.0
    assert ("u_1_1", "m") in model.available_channels()


def test_progress_is_reported_and_a_callback_error_stops_the_run():
    model = poundsim.load(EXAMPLES / "three_buildings_el_centro.toml")
    seen = []
    poundsim.run(model, channels=["V_*"], progress=lambda t, d: seen.append((t, d)), progress_interval=0.0)
    # At every output instant (0, 0.01, … s), and once more at the end.
    assert len(seen) == round(model.duration / model.output_dt) + 2
    assert seen[-1] == (model.duration, model.duration)
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))

    def stop(t, d):
        if t > 1.0:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        poundsim.run(model, channels=["V_*"], progress=stop, progress_interval=0.0)


def test_ctrl_c_stops_a_run_and_raises_keyboard_interrupt():
    # A run of half a minute; SIGINT after 0.3 s must stop it within a second.
    model = poundsim.load(EXAMPLES / "fig2c_ratio0.8.toml",
                          settings=["analysis.duration=90000.0", "analysis.output_dt=1.0"])
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        poundsim.run(model, channels=["V_1"], progress=False)
    assert time.monotonic() - start < 2.0
    timer.join()


def test_runs_release_the_gil():
    model = poundsim.load(EXAMPLES / "three_buildings_el_centro.toml")
    counter = 0
    done = threading.Event()

    def count():
        nonlocal counter
        while not done.is_set():
            counter += 1

    thread = threading.Thread(target=count)
    thread.start()
    try:
        start = counter
        poundsim.run(model, channels=["V_*"], progress=False)
        during = counter - start
    finally:
        done.set()
        thread.join()
    # With the GIL held for the whole run the counter would stand still.
    assert during > 10000
