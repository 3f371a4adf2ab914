"""The cell file format described from the schema: docs/cell-format.md is what `cellstress schema --markdown`
prints (a test, so the two cannot drift), the JSON Schema accepts every built-in cell and a starter cell, and
every field of every record says what it means."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest
import yaml

from cellstress.cell.load import BUILTIN_CELLS, builtin_file, builtin_text
from cellstress.cell.reference import json_schema, markdown
from cellstress.cli import main

DOC = Path(__file__).resolve().parents[2] / "docs" / "cell-format.md"


def test_the_doc_is_generated_from_the_schema() -> None:
    assert DOC.read_text(encoding="utf-8") == markdown(), "run: cellstress schema --markdown > docs/cell-format.md"


def test_every_field_has_a_meaning() -> None:
    schema = json_schema()
    for name, record in [("CellSpec", schema), *schema["$defs"].items()]:
        for field, prop in record.get("properties", {}).items():
            assert prop.get("description"), f"{name}.{field} has no docstring"


@pytest.mark.parametrize("name", BUILTIN_CELLS)
def test_the_json_schema_accepts_the_built_in_cells(name) -> None:
    jsonschema.validate(yaml.safe_load(builtin_text(name)), json_schema())
    assert Path(builtin_file(name)).is_file()


def test_the_json_schema_refuses_what_the_loader_refuses() -> None:
    cell = yaml.safe_load(builtin_text("baseline"))
    cell["robot"]["stopping_time"] = -1.0
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(cell, json_schema())
    cell = yaml.safe_load(builtin_text("baseline"))
    cell["misspelt"] = 1
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(cell, json_schema())


def test_schema_command(capsys) -> None:
    assert main(["schema"]) == 0
    assert json.loads(capsys.readouterr().out) == json_schema()
    assert main(["schema", "--markdown"]) == 0
    assert capsys.readouterr().out == markdown()


def test_new_writes_a_starter_that_passes_check(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["new", "press-line"]) == 0
    text = (tmp_path / "press-line.yaml").read_text()
    assert text.startswith("# yaml-language-server: $schema=cell.schema.json\n")
    assert yaml.safe_load(text)["name"] == "press-line"
    capsys.readouterr()
    assert main(["check", "press-line.yaml"]) == 0
    assert capsys.readouterr().out.strip().endswith("PASS: the cell file is valid and the static check passes")
    jsonschema.validate(yaml.safe_load(text), json_schema())
    # never overwrites, never takes a path for a name
    assert main(["new", "press-line"]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["new", "../escape"]) == 2
    assert not (tmp_path.parent / "escape.yaml").exists()


def test_cells_and_check_say_where_the_files_are(capsys) -> None:
    assert main(["cells"]) == 0
    assert str(Path(builtin_file("baseline")).parent) in capsys.readouterr().out
    assert main(["check", "baseline"]) == 0
    assert f"(built-in: {builtin_file('baseline')}, sha256" in capsys.readouterr().out


@pytest.mark.parametrize("robot", ["panda", "ur5", "z1", "kinova"])
def test_new_with_a_robot_writes_a_starter_that_passes_check(robot, tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["new", "cell", "--robot", robot]) == 0
    text = (tmp_path / "cell.yaml").read_text()
    assert yaml.safe_load(text)["robot"]["urdf"] == robot
    jsonschema.validate(yaml.safe_load(text), json_schema())
    capsys.readouterr()
    assert main(["check", "cell.yaml"]) == 0
    assert capsys.readouterr().out.strip().endswith("PASS: the cell file is valid and the static check passes")


def test_new_refuses_an_unknown_robot(tmp_path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["new", "cell", "--robot", "kuka"]) == 2
    assert "not a built-in robot (ur3, ur5, ur10" in capsys.readouterr().err
    assert not (tmp_path / "cell.yaml").exists()
