"""``cellstress show CELL --program`` and a report's program.png: the robot's program alone over one cycle. The
picture has its size and content, the same cell gives the same bytes, a link that passes through a solid is
drawn in the failure colour (and nothing is, when none does), and the tool's waypoints sit where pinocchio puts
the tool."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import yaml
from PIL import Image

from cellstress.cell.load import builtin_text, load_cell
from cellstress.cli import main
from cellstress.report import draw as D
from cellstress.report.program import FAIL, ProgramPicture, _motion, program_figure
from cellstress.robot.trajectory import evaluate
from cellstress.sim.build import build_layout


def _fail_pixels(path) -> int:
    rgb = np.asarray(Image.open(path).convert("RGB"), dtype=int)
    h = rgb.shape[0]
    target = np.array([int(FAIL[i:i + 2], 16) for i in (1, 3, 5)])
    views = rgb[: int(0.66 * h)]  # the two views (the check's FAIL lines are printed below them)
    return int((np.abs(views - target).sum(axis=2) < 40).sum())


@pytest.fixture(scope="module")
def swing_file(tmp_path_factory):
    data = yaml.safe_load(builtin_text("baseline"))
    data["robot"]["task"]["waypoints_deg"] = [[124.8, -44.8, 78.4, -123.6, -90.0, 0.0],
                                              [124.8, 337.2, 78.4, -123.6, -90.0, 0.0]]  # shoulder +382 deg
    path = tmp_path_factory.mktemp("swing") / "swing.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


def test_show_program_writes_the_same_picture_twice(tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert main(["show", "two-robots", "--program", "--out", str(a)]) == 0
    assert main(["show", "two-robots", "--program", "--out", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    with Image.open(a) as img:
        assert img.size == ProgramPicture().size.pixels
        assert float(np.asarray(img.convert("L"), dtype=float).std()) > 8.0
        assert not any("matplotlib" in str(v).lower() for v in img.info.values())
    assert _fail_pixels(a) == 0
    assert f"wrote     {a}" in capsys.readouterr().out


def test_a_link_through_a_solid_is_drawn_red(swing_file, tmp_path):
    out = tmp_path / "swing.png"
    assert main(["show", str(swing_file), "--program", "--out", str(out)]) == 0
    assert _fail_pixels(out) > 200


def test_default_name_and_a_wrong_suffix(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["show", "baseline", "--program"]) == 0
    assert (tmp_path / "baseline-program.png").is_file()
    assert main(["show", "baseline", "--program", "--out", "x.jpg"]) == 2
    assert "the picture is a PNG file" in capsys.readouterr().err


def test_the_tool_waypoints_are_where_pinocchio_puts_the_tool():
    layout = build_layout(load_cell("two-robots"))
    for r, part in enumerate(layout.robots):
        motion = _motion(layout, r)
        model = pin.buildModelFromUrdf(str(part.model.urdf))
        data = model.createData()
        fid = model.getFrameId("tool0", pin.FrameType.BODY)
        traj = part.trajectory
        for k, tau in enumerate(traj.starts + traj.dwells):
            q, _ = evaluate(traj, float(tau))
            pin.framesForwardKinematics(model, data, part.model.pinocchio_q(q))
            base = np.asarray(layout.params.x_base[r - 1] if r else layout.params.base)
            want = base[:3, :3] @ data.oMf[fid].translation + base[:3, 3]
            np.testing.assert_allclose(motion.waypoints[k], want, atol=1e-9)


def test_a_trajectory_file_is_drawn_as_one_stretch(tmp_path):
    """A trajectory-file program (palletizing, 738 rows): its cycle in one colour, no waypoint numbers."""
    layout = build_layout(load_cell("palletizing"))
    motion = _motion(layout, 0)
    assert motion.a.shape[:2] == (1, 60) and len(motion.waypoints) == 0
    fig = program_figure(layout)
    assert any(t.get_text().startswith("738 moves, cycle 14.76 s") for t in fig.texts)
    D.save_png(fig, tmp_path / "p.png")
    assert _fail_pixels(tmp_path / "p.png") == 0
