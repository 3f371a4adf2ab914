"""Malformed cell files: each must end the CLI with exit code 2 and ONE line on stderr that names the file,
the field and the problem, never a traceback.

Every malformed cell is the built-in baseline, loaded with yaml.safe_load, changed in one place and dumped to
a temporary file, so the tests follow the baseline when its geometry changes.
"""

from __future__ import annotations

import copy
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import pytest
import yaml

from cellstress.cli import main


@pytest.fixture(scope="module")
def baseline() -> dict:
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def _run(args: list[str], capsys) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def _assert_one_line_error(code: int, err: str, *parts: str) -> str:
    assert code == 2, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got:\n{err}"
    line = lines[0]
    assert line.startswith("error: "), line
    for part in parts:
        assert part in line, f"{part!r} not in {line!r}"
    return line


def _index(cell: dict, device_type: str) -> int:
    return next(i for i, d in enumerate(cell["devices"]) if d["type"] == device_type)


# ---- mutations of the baseline: (id, change(cell), field path, words of the problem) -----------------------
def _start(cell: dict) -> tuple[float, float]:
    x, y = cell["human"]["start"]["xy"]
    return float(x), float(y)


def _put_fence_on_start(cell: dict) -> None:
    x, y = _start(cell)
    cell["fences"].append({"points": [[x - 0.5, y], [x + 0.5, y]], "top": 2.0})


def _put_table_on_start(cell: dict) -> None:
    x, y = _start(cell)
    cell["table"]["polygons"].append(
        [[x - 0.3, y - 0.3], [x + 0.3, y - 0.3], [x + 0.3, y + 0.3], [x - 0.3, y + 0.3]]
    )


def _start_off_floor(cell: dict) -> None:
    cell["human"]["start"]["xy"] = [cell["floor"]["xmax"] + 1.0, _start(cell)[1]]


def _short_waypoints(cell: dict) -> None:
    cell["robot"]["task"]["waypoints_deg"] = [w[:-1] for w in cell["robot"]["task"]["waypoints_deg"]]


def _named_start(cell: dict, **extra) -> dict:
    """A ``human.starts`` entry at the cell's start pose."""
    return {"name": "door", **copy.deepcopy(cell["human"]["start"]), **extra}


def _scanner(cell: dict) -> dict:
    return cell["devices"][_index(cell, "laser-scanner")]


def _ssm(name: str = "ssm", **kw) -> dict:
    return {"type": "speed-separation", "name": name, "polygon": [[-1.5, 3.0], [1.5, 3.0], [1.5, 2.0], [-1.5, 2.0]],
            "reaction_time": 0.1, "stopping_time": 0.15, "max_speed": 1.2, **kw}


def _door(i: int) -> dict:
    return {"type": "guard-door", "name": f"door-{i}", "start": [-0.6, -2.0 - i], "end": [0.6, -2.0 - i]}


@dataclass(frozen=True)
class Case:
    id: str
    change: object  # callable(dict) -> None
    field: str | None  # expected field path; None: computed by `field_of`
    problem: tuple[str, ...]
    field_of: object = None  # callable(dict) -> str


CASES = [
    Case("unknown-top-level-key", lambda c: c.update(colour="red"), "colour", ("unknown field",)),
    Case(
        "unknown-nested-key",
        lambda c: c["robot"].update(stoping_time=0.1),
        "robot.stoping_time",
        ("unknown field", "did you mean 'stopping_time'"),
    ),
    Case(
        "unknown-key-in-device",
        lambda c: _scanner(c).update(respons_time=0.1),
        None,
        ("unknown field", "response_time"),
        lambda c: f"devices[{_index(c, 'laser-scanner')}].respons_time",
    ),
    Case(
        "wrong-type", lambda c: c["table"].update(height="high"), "table.height", ("valid number", "'high'")
    ),
    Case(
        "wrong-type-mapping",
        lambda c: c["human"].update(start="door"),
        "human.start",
        ("should be a mapping",),
    ),
    Case(
        "negative-stopping-time",
        lambda c: c["robot"].update(stopping_time=-0.1),
        "robot.stopping_time",
        ("greater than 0", "-0.1"),
    ),
    Case(
        "negative-response-time",
        lambda c: c["devices"][-1].update(response_time=-0.05),
        None,
        ("greater than 0", "-0.05"),
        lambda c: f"devices[{len(c['devices']) - 1}].response_time",
    ),
    Case(
        "zero-dt",
        lambda c: c.setdefault("simulation", {}).update(dt=0.0),
        "simulation.dt",
        ("greater than or equal to 0.001",),
    ),
    Case(
        "table-polygon-2-points",
        lambda c: c["table"].update(polygons=[[[0, 0], [1, 0]]]),
        "table.polygons[0]",
        ("at least 3 points", "got 2"),
    ),
    Case(
        "scanner-polygon-2-points",
        lambda c: _scanner(c).update(polygon=[[0, 0], [1, 0]]),
        None,
        ("at least 3 points",),
        lambda c: f"devices[{_index(c, 'laser-scanner')}].polygon",
    ),
    Case(
        "table-polygon-self-intersecting",
        lambda c: c["table"]["polygons"].append([[5, 5], [6, 6], [6, 5], [5, 6]]),
        None,
        ("intersects itself",),
        lambda c: f"table.polygons[{len(c['table']['polygons']) - 1}]",
    ),
    Case(
        "scanner-polygon-self-intersecting",
        lambda c: _scanner(c).update(polygon=[[-1, 2], [1, 3], [1, 2], [-1, 3]]),
        None,
        ("intersects itself",),
        lambda c: f"devices[{_index(c, 'laser-scanner')}].polygon",
    ),
    Case(
        "missing-urdf",
        lambda c: c["robot"].update(urdf="no_such_robot.urdf"),
        "robot.urdf",
        ("URDF file not found", "no_such_robot.urdf"),
    ),
    Case(
        "unknown-robot-name",
        lambda c: c["robot"].update(urdf="xyz"),
        "robot.urdf",
        ("'xyz' is neither a built-in robot (ur3, ur5, ur10", "panda", "nor a file"),
    ),
    Case(
        "waypoint-beyond-joint-limit",
        lambda c: c["robot"]["task"]["waypoints_deg"][1].__setitem__(2, 900.0),
        "robot.task.waypoints_deg[1][2]",
        ("900 deg is outside joint 'elbow_joint''s limits -180.0..180.0 deg",),
    ),
    Case(
        "two-programs",
        lambda c: c["robot"]["task"].update(trajectory_csv="path.csv"),
        "robot.task",
        ("give exactly one program", "waypoints_deg and trajectory_csv"),
    ),
    Case(
        "speed-scales-count",
        lambda c: c["robot"]["task"].update(speed_scales=[0.5]),
        "robot.task",
        ("speed_scales has 1 value(s); give one per waypoint (2)",),
    ),
    Case(
        "held-joint-twice",
        lambda c: c["robot"].update(hold=[{"joint": "wrist_3_joint", "value": 0.0}] * 2),
        "robot.hold",
        ("held once", "wrist_3_joint"),
    ),
    Case("start-inside-fence", _put_fence_on_start, "human.start.xy", ("fence",)),
    # the safeguards of issue 18: restart, warning field, safety mat
    Case(
        "restart-negative-clear-time",
        lambda c: c["devices"][_index(c, "light-curtain")].update(restart={"automatic": -0.5}),
        None,
        ("greater than 0", "-0.5"),
        lambda c: f"devices[{_index(c, 'light-curtain')}].restart.automatic.automatic",
    ),
    Case(
        "restart-unknown-word",
        lambda c: c["devices"][_index(c, "light-curtain")].update(restart="auto"),
        None,
        ("should be 'manual'", "'auto'"),
        lambda c: f"devices[{_index(c, 'light-curtain')}].restart.manual",
    ),
    Case(
        "warning-speed-above-one",
        lambda c: _scanner(c).update(warning={"polygon": _scanner(c)["polygon"], "reduced_speed": 1.5}),
        None,
        ("less than 1", "1.5"),
        lambda c: f"devices[{_index(c, 'laser-scanner')}].warning.reduced_speed",
    ),
    Case(
        "mat-two-point-polygon",
        lambda c: c["devices"].append({"type": "safety-mat", "name": "mat", "polygon": [[0.0, 2.0], [1.0, 2.0]]}),
        None,
        ("at least 3 points",),
        lambda c: f"devices[{len(c['devices']) - 1}].polygon",
    ),
    Case(
        "too-many-doors",
        lambda c: c["devices"].extend(_door(i) for i in range(5)),
        "devices",
        ("5 guard doors", "at most 4"),
    ),
    Case(
        "door-automatic-restart",
        lambda c: c["devices"].append({**_door(0), "restart": {"automatic": 1.0}}),
        None,
        ("'manual'",),
        lambda c: f"devices[{len(c['devices']) - 1}].restart",
    ),
    Case(
        "door-opening-time-zero",
        lambda c: c["devices"].append({**_door(0), "opening_time": 0}),
        None,
        ("greater than 0",),
        lambda c: f"devices[{len(c['devices']) - 1}].opening_time",
    ),
    Case(
        "muting-ends-before-the-pallet",
        lambda c: c["devices"][_index(c, "light-curtain")].update(muting={"pallet": [1.0, 2.0], "until": 1.5}),
        None,
        ("before the pallet has passed",),
        lambda c: f"devices[{_index(c, 'light-curtain')}].muting",
    ),
    # the cell's clock runs modulo the robot's cycle (the baseline's: 5.71 s): a window must fit in it (issue 29)
    Case(
        "muting-longer-than-the-cycle",
        lambda c: c["devices"][_index(c, "light-curtain")].update(muting={"pallet": [0.0, 2.0], "until": 500.0}),
        None,
        ("lasts 500 s", "longer than the robot's cycle of 5.7"),
        lambda c: f"devices[{_index(c, 'light-curtain')}].muting",
    ),
    Case(
        "muting-after-the-cycle",
        lambda c: c["devices"][_index(c, "light-curtain")].update(muting={"pallet": [7.0, 8.0], "until": 8.0}),
        None,
        ("starts at 7 s", "after the robot's cycle"),
        lambda c: f"devices[{_index(c, 'light-curtain')}].muting",
    ),
    Case(
        "warning-field-inside-the-protective-field",
        lambda c: _scanner(c).update(warning={"polygon": [[p[0] * 0.5, p[1] * 0.5] for p in _scanner(c)["polygon"]]}),
        None,
        ("warning.polygon must contain the protective field", "lies outside the warning field"),
        lambda c: f"devices[{_index(c, 'laser-scanner')}]",
    ),
    # speed and separation monitoring (issue 18)
    Case(
        "ssm-max-speed-zero",
        lambda c: c["devices"].append(_ssm(max_speed=0)),
        None,
        ("greater than 0",),
        lambda c: f"devices[{len(c['devices']) - 1}].max_speed",
    ),
    Case(
        "ssm-automatic-restart",
        lambda c: c["devices"].append(_ssm(restart={"automatic": 1.0})),
        None,
        ("takes no restart field",),
        lambda c: f"devices[{len(c['devices']) - 1}]",
    ),
    Case(
        "ssm-missing-reaction-time",
        lambda c: c["devices"].append({k: v for k, v in _ssm().items() if k != "reaction_time"}),
        None,
        ("required field is missing",),
        lambda c: f"devices[{len(c['devices']) - 1}].reaction_time",
    ),
    Case(
        "ssm-response-beyond-the-queue",
        lambda c: c["devices"].append(_ssm(response_time=2.0)),
        None,
        ("must be at most",),
        lambda c: f"devices[{len(c['devices']) - 1}].response_time",
    ),
    Case(
        "ssm-two-devices",
        lambda c: c["devices"].extend([_ssm("ssm-a"), _ssm("ssm-b")]),
        None,
        ("one speed-separation device",),
        lambda c: f"devices[{len(c['devices']) - 1}]",
    ),
    Case("start-inside-table", _put_table_on_start, "human.start.xy", ("table",)),
    Case("start-off-floor", _start_off_floor, "human.start.xy", ("not on the floor",)),
    Case(
        "waypoint-wrong-joint-count",
        _short_waypoints,
        "robot.task.waypoints_deg[0]",
        ("joint values but the robot has", "joints"),
    ),
    Case(
        "waypoints-mixed-lengths",
        lambda c: c["robot"]["task"]["waypoints_deg"][1].append(0.0),
        "robot.task.waypoints_deg",
        ("same number of joints",),
    ),
    Case(
        "unknown-device-type",
        lambda c: c["devices"][0].update(type="radar"),
        "devices[0].type",
        ("unknown device type 'radar'", "laser-scanner"),
    ),
    Case(
        "missing-device-type",
        lambda c: c["devices"][0].pop("type"),
        "devices[0].type",
        ("required field is missing",),
    ),
    Case(
        "duplicate-device-names",
        lambda c: c["devices"].append(copy.deepcopy(c["devices"][0])),
        "devices",
        ("unique", "both named"),
    ),
    Case(
        "fence-top-below-bottom",
        lambda c: c["fences"][0].update(top=0.5, bottom=1.0),
        "fences[0]",
        ("top (0.5) must be above bottom (1.0)",),
    ),
    Case("missing-required-field", lambda c: c.pop("name"), "name", ("required field is missing",)),
    Case(
        "point-with-two-coordinates",
        lambda c: c["robot"]["base"].update(xyz=[0.0, 0.0]),
        "robot.base.xyz",
        ("needs 3 values, got 2",),
    ),
    Case("not-a-number", lambda c: c["floor"].update(xmax=float("nan")), "floor.xmax", ("finite",)),
    Case(
        "capsules-neither-auto-nor-list",
        lambda c: c["robot"].update(capsules="manual"),
        "robot.capsules",
        ("'auto' or a list of capsules",),
    ),
    Case("worker-model-unknown", lambda c: c["human"].update(model="robot"), "human.model",
         ("'paper'", "'articulated'")),
    Case("body-size-unknown", lambda c: c["human"].update(body="p99-giant"), "human.body", ("'p95-male'",)),
    Case("body-and-anthropometry", lambda c: c["human"].update(body="p5-female", anthropometry={"height": 1.9}),
         "human", ("give body (p5-female) or anthropometry, not both",)),
    Case(
        "start-phase-negative",
        lambda c: c["human"].update(starts=[_named_start(c, phase=-1.5)]),
        "human.starts[0].phase",
        ("greater than or equal to 0", "-1.5"),
    ),
    Case(
        "start-phase-not-a-number",
        lambda c: c["human"].update(starts=[_named_start(c, phase="late")]),
        "human.starts[0].phase",
        ("valid number", "'late'"),
    ),
    Case(
        "start-phase-infinite",
        lambda c: c["human"].update(starts=[_named_start(c, phase=float("inf"))]),
        "human.starts[0].phase",
        ("finite",),
    ),
    Case(
        "capsule-on-unknown-link",
        lambda c: c["robot"].update(
            extra_capsules=[{"link": "hand", "p0": [0, 0, 0], "p1": [0, 0, 0.1], "radius": 0.05}]
        ),
        "robot.extra_capsules[0].link",
        ("no link 'hand'",),
    ),
]


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_malformed_cell(case: Case, baseline: dict, tmp_path: Path, capsys) -> None:
    cell = copy.deepcopy(baseline)
    case.change(cell)
    path = tmp_path / f"{case.id}.yaml"
    path.write_text(yaml.safe_dump(cell, sort_keys=False), encoding="utf-8")
    field = case.field if case.field is not None else case.field_of(cell)
    code, out, err = _run(["check", str(path)], capsys)
    line = _assert_one_line_error(code, err, str(path), *case.problem)
    assert f": {field}: " in line, f"field {field!r} not named in {line!r}"
    assert out == ""


# ---- files that are not a cell mapping at all --------------------------------------------------------------
RAW = [
    ("yaml-syntax-error", b"name: [baseline\nrobot: {}\n", "line 2", ("YAML syntax error",)),
    ("yaml-tab-indent", b"name: x\nrobot:\n\turdf: ur10\n", "line 3", ("YAML syntax error",)),
    ("empty-file", b"", None, ("the file is empty",)),
    ("comments-only", b"# nothing here\n", None, ("the file is empty",)),
    ("yaml-list", b"- name: baseline\n- robot: {}\n", "(top level)", ("mapping", "not a list")),
    ("yaml-scalar", b"42\n", "(top level)", ("mapping", "not a single number")),
    ("non-utf8", b"name: x\ndescription: caf\xe9\n", "line 2, column 17", ("not UTF-8",)),
    ("duplicate-key", b"name: a\nname: b\n", "line 2", ("duplicate key 'name'",)),
    (
        "python-object-tag",
        b"!!python/object:os.system {}\n",
        "line 1",
        ("!!python/object:os.system", "not allowed"),
    ),
]


@pytest.mark.parametrize("name,content,field,problem", RAW, ids=[r[0] for r in RAW])
def test_malformed_file(name, content, field, problem, tmp_path: Path, capsys) -> None:
    path = tmp_path / f"{name}.yaml"
    path.write_bytes(content)
    code, out, err = _run(["check", str(path)], capsys)
    line = _assert_one_line_error(code, err, str(path), *problem)
    if field:
        assert f": {field}" in line
    assert out == ""


def test_python_apply_tag_is_not_executed(tmp_path: Path, capsys) -> None:
    marker = tmp_path / "executed"
    path = tmp_path / "evil.yaml"
    path.write_text(f"name: !!python/object/apply:os.system ['touch {marker}']\n", encoding="utf-8")
    code, _, err = _run(["check", str(path)], capsys)
    _assert_one_line_error(code, err, str(path), "!!python/object/apply:os.system", "not allowed")
    assert not marker.exists()


def test_directory_instead_of_file(tmp_path: Path, capsys) -> None:
    code, _, err = _run(["check", str(tmp_path)], capsys)
    _assert_one_line_error(code, err, str(tmp_path), "is a directory")


def test_file_that_does_not_exist(tmp_path: Path, capsys) -> None:
    path = tmp_path / "nope.yaml"
    code, _, err = _run(["simulate", str(path), "--actions", "walk+upright"], capsys)
    _assert_one_line_error(code, err, str(path), "no such file", "baseline")


def test_unknown_action_name(capsys) -> None:
    code, out, err = _run(["simulate", "baseline", "--actions", "walk+upright,fly+upright"], capsys)
    _assert_one_line_error(code, err, "--actions", "unknown action 'fly+upright'", "WALK+BODY")
    assert out == ""


def test_empty_action_list(capsys) -> None:
    code, _, err = _run(["simulate", "baseline", "--actions", " , "], capsys)
    _assert_one_line_error(code, err, "--actions", "empty")


def test_bad_cell_with_simulate(baseline: dict, tmp_path: Path, capsys) -> None:
    """simulate reports cell errors the same way as check."""
    cell = copy.deepcopy(baseline)
    cell["robot"]["stopping_time"] = -1
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(cell), encoding="utf-8")
    code, _, err = _run(["simulate", str(path), "--actions", "walk+upright"], capsys)
    _assert_one_line_error(code, err, str(path), "robot.stopping_time", "greater than 0")


def test_only_the_first_problem_and_a_count(baseline: dict, tmp_path: Path, capsys) -> None:
    cell = copy.deepcopy(baseline)
    cell["robot"]["stopping_time"] = -1
    cell["table"]["height"] = -1
    path = tmp_path / "two.yaml"
    path.write_text(yaml.safe_dump(cell, sort_keys=False), encoding="utf-8")
    code, _, err = _run(["check", str(path)], capsys)
    _assert_one_line_error(code, err, "robot.stopping_time", "and 1 more problem")


# ---- the real console script, in a fresh process -----------------------------------------------------------
def _script() -> list[str]:
    exe = shutil.which("cellstress", path=str(Path(sys.executable).parent))
    return [exe] if exe else [sys.executable, "-m", "cellstress.cli"]


@pytest.mark.parametrize(
    "content,problem",
    [
        (b"name: [x\n", "YAML syntax error"),
        (b"!!python/object/new:os.system [echo hi]\n", "not allowed"),
        (b"\xff\xfe\x00", "not UTF-8"),
        (b"name: x\nrobot: 3\n", "robot"),
    ],
    ids=["yaml", "python-tag", "binary", "wrong-type"],
)
def test_console_script_bad_file(content: bytes, problem: str, tmp_path: Path) -> None:
    path = tmp_path / "bad.yaml"
    path.write_bytes(content)
    proc = subprocess.run(
        [*_script(), "check", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "NO_COLOR": "1"},
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert (
        len(lines) == 1 and lines[0].startswith("error: ") and str(path) in lines[0] and problem in lines[0]
    )
    assert proc.stdout == ""
