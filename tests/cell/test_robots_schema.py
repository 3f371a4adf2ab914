"""Cell files with several robots (issue 17): ``robot`` or ``robots``, names, and the devices' ``stops``; every
mistake is exit code 2 and one line naming the file and the field."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from cellstress.cell.load import builtin_text, load_cell
from cellstress.cli import main


@pytest.fixture(scope="module")
def two() -> dict:
    return yaml.safe_load(builtin_text("two-robots"))


def _third(c: dict, name: str = "c") -> dict:
    r = copy.deepcopy(c["robots"][0])
    r["name"] = name
    return r


CASES = [
    ("unknown-robot-in-stops", lambda c: c["devices"][0].update(stops=["a", "z"]), "devices[0].stops[1]",
     ("no robot is named 'z'", "a, b")),
    ("robot-twice-in-stops", lambda c: c["devices"][0].update(stops=["a", "a"]), "devices[0].stops[1]",
     ("twice",)),
    ("empty-stops", lambda c: c["devices"][0].update(stops=[]), "devices[0].stops", ("at least 1",)),
    ("duplicate-robot-names", lambda c: c["robots"][1].update(name="a"), "robots[1].name", ("unique",)),
    ("robot-and-robots", lambda c: c.update(robot=copy.deepcopy(c["robots"][0])), "",
     ("exactly one of robot", "not both")),
    ("neither-robot-nor-robots", lambda c: c.pop("robots"), "", ("exactly one of robot",)),
    ("too-many-robots", lambda c: c["robots"].extend([_third(c, n) for n in ("c", "d", "e")]), "robots",
     ("too many", "expected 4, got 5")),
    ("robot-name-not-identifier", lambda c: c["robots"][0].update(name="a<b>"), "robots[0].name",
     ("should match pattern",)),
    ("bad-link-of-second-robot", lambda c: c["robots"][1].update(extra_capsules=[
        {"link": "nope", "p0": [0, 0, 0], "p1": [0, 0, 0.1], "radius": 0.05}]), "robots[1].extra_capsules[0].link",
     ("no link 'nope'",)),
    ("bad-program-of-second-robot", lambda c: c["robots"][1]["task"].update(speed_scales=[0.5]),
     "robots[1].task", ("one per waypoint",)),
    ("automatic-restart-with-two-robots", lambda c: c["devices"][0].update(restart={"automatic": 0.5}),
     "devices[0]", ("automatic restart", "several robots")),
    ("speed-separation-with-two-robots", lambda c: c["devices"].append(
        {"type": "speed-separation", "name": "ssm", "polygon": [[-1.0, 3.0], [1.0, 3.0], [1.0, 2.5], [-1.0, 2.5]],
         "reaction_time": 0.3, "stopping_time": 0.15, "max_speed": 1.2}),
     f"devices[{len(yaml.safe_load(builtin_text('two-robots'))['devices'])}]",
     ("speed and separation monitoring", "several robots")),
]


@pytest.mark.parametrize(("change", "field", "words"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_robots_input(two: dict, tmp_path: Path, capsys, change, field, words) -> None:
    cell = copy.deepcopy(two)
    change(cell)
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(cell, sort_keys=False), encoding="utf-8")
    code = main(["check", str(path)])
    out, err = capsys.readouterr()
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert str(path) in lines[0]
    if field:
        assert f": {field}: " in lines[0], lines[0]
    for w in words:
        assert w in lines[0], lines[0]
    assert out == ""


def test_robot_is_a_list_of_one() -> None:
    spec = load_cell("baseline").spec
    assert spec.robots == (spec.robot,)
    assert spec.robot.name == "robot"
    two = load_cell("two-robots").spec
    assert two.robot is two.robots[0]
    assert [r.name for r in two.robots] == ["a", "b"]
    assert two.devices[0].stops == ("a",)
    assert load_cell("two-robots-fixed").spec.devices[0].stops == ("a", "b")
