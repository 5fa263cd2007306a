"""Every CSV file the command line writes declares its columns' units beside it
(<file>-metadata.json, W3C CSV on the Web), and the module takes the units from there."""

import json
import pathlib
import re
import shutil

import pytest

from support import EXAMPLES, cli_run, read_csv

import poundsim.results as results

RUNS = {
    "time_history": (EXAMPLES / "three_buildings_el_centro.toml", ["analysis.duration=2"]),
    "frequency_response": (EXAMPLES / "paper" / "fig2c.toml", ["frf.points=12"]),
    "study": (EXAMPLES / "study_eta_mu.toml", []),
    "optimize": (EXAMPLES / "optimize_gap_elements.toml", []),
}


@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    out = {}
    for name, (model, settings) in RUNS.items():
        out[name] = cli_run(model, tmp_path_factory.mktemp(name), *settings)
    return out


def metadata(csv_path: pathlib.Path) -> dict:
    with open(str(csv_path) + "-metadata.json") as f:
        return json.load(f)


def test_every_csv_declares_its_columns_in_order_with_datatype_and_unit(folders):
    seen = 0
    for folder in folders.values():
        for path in sorted(folder.glob("*.csv")):
            header, rows = read_csv(path)
            meta = metadata(path)
            assert meta["@context"] == "http://www.w3.org/ns/csvw"
            assert meta["url"] == path.name
            columns = meta["tableSchema"]["columns"]
            assert [c["titles"] for c in columns] == header, path
            for k, c in enumerate(columns):
                assert c["datatype"] in ("number", "integer", "string"), (path, c)
                assert isinstance(c["schema:unitText"], str)
                values = [r[k] for r in rows if r[k] != ""]
                if c["datatype"] == "integer":
                    assert all(re.fullmatch(r"-?\d+", v) for v in values), (path, c["titles"])
                elif c["datatype"] == "number":
                    for v in values:
                        float(v)  # raises on text
            seen += 1
    assert seen >= 6  # history, events, frf, study, evaluations and an optimum's frf at least


def test_history_units_agree_with_the_channels_declared_in_python(folders):
    path = folders["time_history"] / "history.csv"
    units = {c["titles"]: c["schema:unitText"] for c in metadata(path)["tableSchema"]["columns"]}
    assert units["t_s"] == "s"
    assert any(u == "m/s2" for u in units.values()) and any(u == "N" for u in units.values())
    for column, unit in units.items():
        channel, named = results.channel_of_column(column)
        assert named == unit, column


def test_event_and_table_units(folders):
    events = {c["titles"]: c["schema:unitText"]
              for c in metadata(folders["time_history"] / "events.csv")["tableSchema"]["columns"]}
    assert events["impulse_Ns"] == "N·s"
    assert events["relative_velocity_before_m_s"] == "m/s"
    assert events["kind"] == "" and events["floor"] == ""
    frf = {c["titles"]: c["schema:unitText"]
           for c in metadata(folders["frequency_response"] / "frf.csv")["tableSchema"]["columns"]}
    assert frf["ratio"] == "1" and frf["V1_W"] == "1"


def test_results_take_units_from_the_metadata_not_the_names(folders, tmp_path):
    copy = tmp_path / "history"
    shutil.copytree(folders["time_history"], copy)
    meta_path = copy / "history.csv-metadata.json"
    meta = json.loads(meta_path.read_text())
    column = next(c for c in meta["tableSchema"]["columns"] if c["titles"].startswith("u_"))
    assert column["schema:unitText"] == "m"
    # The same column declared in millimetres: the channel is then its name without "_mm".
    column["titles"] = column["titles"][: -len("_m")] + "_mm"
    column["schema:unitText"] = "mm"
    meta_path.write_text(json.dumps(meta))
    header, rows = read_csv(copy / "history.csv")
    header[header.index(column["titles"][: -len("_mm")] + "_m")] = column["titles"]
    (copy / "history.csv").write_text("\n".join(",".join(r) for r in [header] + rows) + "\n")
    run = results.read(copy)
    channel = column["titles"][: -len("_mm")]
    assert run.unit(channel) == "mm"

    study = results.read(folders["study"])
    declared = {c["titles"]: c["schema:unitText"]
                for c in metadata(folders["study"] / "study.csv")["tableSchema"]["columns"]}
    assert study.table.units == declared


def test_metadata_that_does_not_match_its_file_is_refused(folders, tmp_path):
    copy = tmp_path / "frf"
    shutil.copytree(folders["frequency_response"], copy)
    meta_path = copy / "frf.csv-metadata.json"
    meta = json.loads(meta_path.read_text())
    meta["tableSchema"]["columns"].pop()
    meta_path.write_text(json.dumps(meta))
    with pytest.raises(ValueError, match="declares the columns"):
        results.Table.read_csv(copy / "frf.csv")
