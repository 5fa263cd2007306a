"""The JSON Schema of model files (`poundsim schema`, poundsim.input_schema()): valid for every
file the reader accepts, refusing what the reader refuses as a key or a type."""

import copy
import json
import re
import subprocess
import tomllib

import jsonschema
import pytest

import poundsim
from support import CLI, SOURCE

# Malformed cases whose unknown key the schema cannot see: a study point's or a starting point's
# key (a value, not a key of the file), or a record file's content.
NOT_A_KEY_OF_THE_FILE = {"optimize_variable_unknown_key.toml", "study_parameter_unknown_key.toml"}


@pytest.fixture(scope="module")
def validator():
    schema = poundsim.input_schema()
    jsonschema.Draft7Validator.check_schema(schema)
    return jsonschema.Draft7Validator(schema)


def model_files():
    """Every model file of the examples and the tests that the reader accepts."""
    files = sorted(SOURCE.glob("examples/**/*.toml")) + sorted(SOURCE.glob("tests/**/*.toml"))
    return [f for f in files if "malformed" not in f.parts and "analysis" in tomllib.loads(f.read_text())]


def test_the_command_writes_the_modules_schema(tmp_path):
    out = tmp_path / "poundsim.schema.json"
    subprocess.run([CLI, "schema", "--out", str(out)], check=True)
    assert json.loads(out.read_text()) == poundsim.input_schema()
    printed = subprocess.run([CLI, "schema"], check=True, capture_output=True, text=True).stdout
    assert json.loads(printed) == poundsim.input_schema()


def test_the_committed_schema_is_current():
    """docs/poundsim.schema.json, for editors pointed at the repository, is what the program writes."""
    assert json.loads((SOURCE / "docs" / "poundsim.schema.json").read_text()) == poundsim.input_schema()


def test_the_schema_carries_the_declared_ranges_defaults_and_names():
    schema = poundsim.input_schema()
    frf = schema["properties"]["frf"]["properties"]
    assert frf["steps_per_period"]["minimum"] == 8
    assert frf["amplitude_g"]["description"].endswith("[g]")
    assert "amplitude_g" in schema["properties"]["frf"]["required"]
    analysis = schema["properties"]["analysis"]
    assert analysis["required"] == ["kind"]
    assert analysis["properties"]["kind"]["enum"] == ["time_history", "frf", "continuation", "ensemble", "study",
                                                       "optimize"]
    gaps = schema["properties"]["gap_elements"]
    assert gaps["properties"]["law"]["default"] == "paper"
    laws = [branch["if"]["properties"]["law"]["const"] for branch in gaps["allOf"] if "properties" in branch["if"]]
    assert laws == gaps["properties"]["law"]["enum"]
    assert schema["properties"]["frames"]["type"] == "array"
    assert schema["properties"]["excitation"]["properties"]["units"]["enum"] == ["g", "m/s2", "cm/s2"]


@pytest.mark.parametrize("path", model_files(), ids=lambda p: str(p.relative_to(SOURCE)))
def test_every_accepted_model_file_is_valid(validator, path):
    errors = [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(tomllib.loads(path.read_text()))]
    assert errors == []


def tables_of(document, path=()):
    """Every table of a document (dicts, and dicts in arrays of tables), with its path."""
    yield path, document
    for key, value in document.items():
        if isinstance(value, dict):
            yield from tables_of(value, path + (key,))
        elif isinstance(value, list) and value and all(isinstance(item, dict) for item in value):
            for i, item in enumerate(value):
                yield from tables_of(item, path + (key, i))


@pytest.mark.parametrize("path", sorted(SOURCE.glob("examples/**/*.toml")), ids=lambda p: p.name)
def test_a_misspelt_key_in_any_table_is_invalid(validator, path):
    document = tomllib.loads(path.read_text())
    for where, _ in list(tables_of(document)):
        changed = copy.deepcopy(document)
        table = changed
        for step in where:
            table = table[step]
        table["stifness"] = 1.0
        assert not validator.is_valid(changed), f"{path.name}: a misspelt key in {where} is valid"


def refused_as_key_or_type(text):
    expected = re.findall(r"^# expect: (.*)$", text, re.M)
    return any(re.search(r"unknown (key|table)|expected a|is not one of", e) for e in expected)


def test_the_malformed_cases_of_keys_and_types_are_invalid(validator):
    checked, valid = 0, []
    for case in sorted(SOURCE.glob("tests/malformed/*.toml")):
        text = case.read_text()
        if case.name in NOT_A_KEY_OF_THE_FILE or "# args:" in text or not refused_as_key_or_type(text):
            continue
        try:
            document = tomllib.loads(text)
        except tomllib.TOMLDecodeError:
            continue  # not TOML: refused before any schema applies
        if validator.is_valid(document):
            valid.append(case.name)
        checked += 1
    assert valid == []
    assert checked >= 9
