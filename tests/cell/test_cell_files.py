"""cell.files: every file a cell reads, with size and SHA-256 (check lists them, result files record them,
replay names the one that changed), and CELLSTRESS_FILES=inside, which refuses files outside the cell's folder
before they are read (issue 29)."""

from __future__ import annotations

import hashlib
import os
import shutil
from importlib import resources
from pathlib import Path

import pytest
import yaml

from cellstress.cell.files import shown_path
from cellstress.cell.load import load_cell
from cellstress.cli import main
from cellstress.core.errors import CellError
from cellstress.robot.model import resolve_urdf

MESHES = "example-robot-data/robots/ur_description/meshes/ur10/collision"


def _baseline() -> dict:
    return yaml.safe_load(resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text())


@pytest.fixture
def own_robot(tmp_path) -> Path:
    """The baseline in a folder of its own, with a copy of the UR10's URDF and its collision meshes (the URDF's
    package:// paths find the copies first: its own folder is searched first)."""
    cell = tmp_path / "cell"
    urdf = resolve_urdf("ur10", None)
    shutil.copytree(urdf.parents[1] / "meshes" / "ur10" / "collision", cell / MESHES)
    shutil.copy(urdf, cell / "ur10.urdf")
    doc = _baseline()
    doc["robot"]["urdf"] = "ur10.urdf"
    (cell / "cell.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    return cell / "cell.yaml"


def _digest(path: Path) -> tuple[int, str]:
    data = path.read_bytes()
    return len(data), hashlib.sha256(data).hexdigest()


def test_every_file_with_its_size_and_hash(own_robot):
    cell = load_cell(own_robot)
    folder = own_robot.parent
    expected = [("cell", own_robot), ("robot.urdf", folder / "ur10.urdf")] + [
        ("robot.urdf mesh", folder / MESHES / f"{n}.stl")
        for n in ("base", "shoulder", "upperarm", "forearm", "wrist1", "wrist2", "wrist3")]
    assert [(f.use, f.path) for f in cell.files] == [(u, str(p)) for u, p in expected]
    for f, (_, p) in zip(cell.files, expected, strict=True):
        assert (f.bytes, f.sha256) == _digest(p)  # computed here independently


def test_shipped_files_are_named_the_same_on_every_machine():
    cell = load_cell("palletizing")
    assert [f.path for f in cell.files][:2] == ["cellstress:cell/builtin/palletizing.yaml",
                                                "example-robot-data:robots/panda_description/urdf/panda.urdf"]
    assert cell.files[-1].path == "cellstress:cell/builtin/palletizing.csv"
    assert all(":" in f.path and not f.path.startswith("/") for f in cell.files)


def test_check_lists_them_and_marks_those_outside(own_robot, tmp_path, capsys):
    outside = tmp_path / "elsewhere" / "ur10.urdf"
    outside.parent.mkdir()
    (own_robot.parent / "ur10.urdf").rename(outside)
    (own_robot.parent / "ur10.urdf").symlink_to(outside)  # a link in the folder to a file outside it
    code = main(["check", str(own_robot)])
    out = capsys.readouterr().out
    assert code == 0
    assert "files       9 read; 1 outside the cell's folder (CELLSTRESS_FILES=inside refuses them)" in out
    size, digest = _digest(outside)
    assert f"robot.urdf               {outside}  ({size:,} bytes, sha256 {digest})  OUTSIDE the cell's folder" in out


@pytest.mark.parametrize("how", ["absolute", "dotdot", "home", "link"])
def test_confined_a_file_outside_is_refused_before_it_is_read(tmp_path, monkeypatch, how):
    """The trajectory file outside the folder is a FIFO: reading it would say so (or block); refused first."""
    cell = tmp_path / "cell"
    cell.mkdir()
    os.mkfifo(tmp_path / "q.csv")
    ref = {"absolute": str(tmp_path / "q.csv"), "dotdot": "../q.csv", "home": "~/q.csv", "link": "q.csv"}[how]
    if how == "link":
        (cell / "q.csv").symlink_to(tmp_path / "q.csv")
    monkeypatch.setenv("HOME", str(tmp_path))
    doc = _baseline()
    doc["robot"]["task"] = {"trajectory_csv": ref}
    (cell / "cell.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    monkeypatch.setenv("CELLSTRESS_FILES", "inside")
    with pytest.raises(CellError) as err:
        load_cell(cell / "cell.yaml")
    assert err.value.field == "robot.task.trajectory_csv"
    assert f"is {tmp_path / 'q.csv'}, outside the cell's folder {cell}" in err.value.problem
    monkeypatch.setenv("CELLSTRESS_FILES", "anywhere")  # the default: read (a FIFO is refused as such)
    with pytest.raises(CellError, match="not a regular file"):
        load_cell(cell / "cell.yaml")


def test_confined_a_mesh_outside_is_refused(own_robot, tmp_path, monkeypatch):
    urdf = own_robot.parent / "ur10.urdf"
    base = own_robot.parent / MESHES / "base.stl"
    moved = tmp_path / "base.stl"
    base.rename(moved)
    urdf.write_text(urdf.read_text().replace(
        "package://example-robot-data/robots/ur_description/meshes/ur10/collision/base.stl", f"file://{moved}"))
    assert load_cell(own_robot).files[2].path == str(moved)
    monkeypatch.setenv("CELLSTRESS_FILES", "inside")
    with pytest.raises(CellError) as err:
        load_cell(own_robot)
    assert err.value.field == "robot.urdf" and f"names the mesh {moved}, outside the cell's folder" in str(err.value)


def test_confined_shipped_robots_and_cells_are_inside(monkeypatch):
    monkeypatch.setenv("CELLSTRESS_FILES", "inside")
    assert load_cell("palletizing").files
    assert load_cell("two-robots").files


def test_an_unknown_rule_is_an_error(monkeypatch):
    monkeypatch.setenv("CELLSTRESS_FILES", "everywhere")
    with pytest.raises(Exception, match="CELLSTRESS_FILES='everywhere': must be 'anywhere'"):
        load_cell("baseline")


def test_a_mesh_that_is_not_a_file_is_refused_before_it_is_hashed(own_robot):
    base = own_robot.parent / MESHES / "base.stl"
    base.unlink()
    os.mkfifo(base)
    with pytest.raises(CellError) as err:
        load_cell(own_robot)
    assert err.value.field == "robot.urdf" and "not a regular file" in err.value.problem


def test_replay_names_the_file_that_changed(tmp_path, capsys):
    folder = tmp_path / "pal"
    builtin = resources.files("cellstress.cell").joinpath("builtin")
    folder.mkdir()
    for name in ("palletizing.yaml", "palletizing.csv"):
        (folder / name).write_bytes(builtin.joinpath(name).read_bytes())
    out = tmp_path / "out"
    assert main(["search", str(folder / "palletizing.yaml"), "--searcher", "plan", "--budget", "20", "--out",
                 str(out), "--no-report"]) == 0
    assert main(["replay", str(out / "result.json"), "--no-search"]) == 0
    with (folder / "palletizing.csv").open("a") as f:
        f.write("\n")  # a blank row: the same program, other bytes
    capsys.readouterr()
    assert main(["replay", str(out / "result.json"), "--no-search"]) == 1
    mismatches = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("MISMATCH")]
    assert mismatches == [f"MISMATCH: cell.files: {folder / 'palletizing.csv'} (robot.task.trajectory_csv) has "
                          "changed (sha256 cf3da51c9417 recorded, "
                          f"{hashlib.sha256((folder / 'palletizing.csv').read_bytes()).hexdigest()[:12]} now; "
                          "52,822 bytes recorded, 52,823 now)"]
    assert main(["report", str(out / "result.json")]) == 0  # the report says so too
    assert "the cell file, or a file it reads, has changed since the search" in capsys.readouterr().out


def test_shown_path_resolves_links(tmp_path):
    (tmp_path / "real.txt").write_text("x")
    (tmp_path / "link.txt").symlink_to(tmp_path / "real.txt")
    assert shown_path(tmp_path / "link.txt") == str(tmp_path / "real.txt")
