"""``analysis.cell_diff``: the loaded models compared field by field (not the text), check rows matched by
name, hazard classes by the search's key."""

from __future__ import annotations

from importlib import resources

import yaml

from cellstress.analysis.cell_diff import field_changes, row_changes
from cellstress.analysis.check_rows import CheckRow
from cellstress.cell.load import load_cell


def _write(tmp_path, name: str, doc: dict):
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return load_cell(path)


def _baseline() -> dict:
    return yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text("utf-8"))


def test_text_alone_is_no_change(tmp_path):
    doc = _baseline()
    a = _write(tmp_path, "a", doc)
    doc["description"] = "other words"
    b = _write(tmp_path, "b", doc)
    # the same model written another way: keys reordered, a default written out
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(dict(reversed(list(_baseline().items()))), sort_keys=True),
                                     encoding="utf-8")
    assert field_changes(a, b) == ()
    assert field_changes(a, load_cell(tmp_path / "c.yaml")) == ()


def test_each_part_is_named(tmp_path):
    doc = _baseline()
    a = _write(tmp_path, "a", doc)
    doc["robot"]["task"]["speed_scale"] = 0.4
    doc["robot"]["stopping_time"] = 0.2
    doc["fences"][0]["top"] = 2.2
    doc["devices"] = list(reversed(doc["devices"]))  # order alone: devices are matched by name
    doc["devices"][0]["response_time"] = doc["devices"][0]["response_time"] + 0.01
    b = _write(tmp_path, "b", doc)
    got = {(c.section, c.path) for c in field_changes(a, b)}
    dev = doc["devices"][0]["name"]
    assert got == {("program", "robots[robot].task.speed_scale"), ("stopping", "robots[robot].stopping_time"),
                   ("geometry", "fences[1].top"), ("devices", f"devices[{dev}].response_time")}
    change = next(c for c in field_changes(a, b) if c.section == "program")
    assert (change.old, change.new) == ("0.5", "0.4")
    doc["devices"] = doc["devices"][1:]
    gone = {(c.section, c.path, c.new) for c in field_changes(a, _write(tmp_path, "c", doc))}
    assert ("devices", f"devices[{dev}]", "") in gone


def test_rows_matched_by_name():
    old = (CheckRow("a", "k", True, "1 m", ""), CheckRow("b", "k", True, "2 m", ""), CheckRow("c", "k", True, "", ""))
    new = (CheckRow("b", "k", False, "2 m", ""), CheckRow("a", "k", True, "1.5 m", ""),
           CheckRow("d", "k", True, "", ""))
    got = {(r.name, r.change) for r in row_changes(old, new)}
    assert got == {("a", "value"), ("b", "verdict"), ("c", "removed"), ("d", "added")}
    assert row_changes(old, old) == ()
