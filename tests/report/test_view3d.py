"""The 3D view's data is the simulator's geometry (checked against the kernels' arrays and independent
distances), the page is self-contained, the same result gives the same bytes, and a 16-action episode with two
robots stays within the size budget."""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser

import numpy as np
import pytest

from cellstress.report.scene3d import ViewData, reach_kept, triangulate, view_of_episodes
from cellstress.report.view3d import view_fragment
from cellstress.sim import scene

SIZE_BUDGET = 10 * 1024 * 1024  # bytes: docs/architecture.md, "The 3D view"


def _data(html: str) -> dict:
    m = re.search(r'<script type="application/json" id="cs3d-data">(.*?)</script>', html, flags=re.S)
    return json.loads(m.group(1))


def _polygon_area(p) -> float:
    p = np.asarray(p, float)
    return 0.5 * abs(float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])))


@pytest.mark.parametrize("poly", [
    [(0, 0), (1, 0), (1, 1), (0, 1)],
    [(-1.0, -0.4), (1.0, -0.4), (1.0, 1.2), (0.45, 1.2), (0.45, 0.3), (-0.45, 0.3), (-0.45, 1.2), (-1.0, 1.2)],
    [(0, 0), (0, 2), (2, 2), (2, 1.5), (0.5, 1.5), (0.5, 0.5), (2, 0.5), (2, 0)],  # clockwise C shape
])
def test_triangles_cover_the_polygon_exactly(poly) -> None:
    tris = triangulate(poly)
    assert len(tris) == len(poly) - 2
    p = np.asarray(poly, float)
    areas = [_polygon_area(p[list(t)]) for t in tris]
    assert min(areas) > 0
    assert sum(areas) == pytest.approx(_polygon_area(poly), rel=1e-12)


def test_episode_data_is_the_simulators_geometry(s1_witness_view) -> None:
    view = s1_witness_view
    layout = view.layout
    doc = json.loads(view_of_episodes(layout, [(view, "w")]).to_json())
    ep, cell = doc["episodes"][0], doc["cell"]
    assert ep["n"] == len(view.records)
    # robot capsules at every step: the kernel's forward kinematics at the step's path time, in mm
    for i in (0, ep["n"] // 2, ep["n"] - 1):
        a, b = scene.robot_capsules(layout, view.taus[i])
        got = np.asarray(ep["robot"][i], float).reshape(-1, 6) / 1000.0
        assert np.abs(got[:, :3] - a).max() <= 0.0005 and np.abs(got[:, 3:] - b).max() <= 0.0005
    # the fence panels are the kernel's rows, the fields its channels
    assert np.abs(np.asarray([p["rect"] for p in cell["panels"]]) / 1000.0 - layout.params.fences).max() <= 0.0005
    assert [f["name"] for f in cell["fields"]] == list(layout.device_names)
    # an independent check of the contact marker: the robot point lies on the touching link's capsule surface,
    # the human point d_HR from it
    m = ep["marker"]
    hit = view.records[m["step"]]
    assert m["kind"] == "contact" and m["step"] == len(view.records) - 1
    ab = np.asarray(ep["robot"][m["step"]], float).reshape(-1, 6)[m["link"]] / 1000.0
    rp, hp = np.asarray(m["rp"]) / 1000.0, np.asarray(m["hp"]) / 1000.0
    a, b = ab[:3], ab[3:]
    length2 = float(np.dot(b - a, b - a))
    t = 0.0 if length2 < 1e-12 else float(np.clip(np.dot(rp - a, b - a) / length2, 0.0, 1.0))
    radius = cell["link_r"][m["link"]] / 1000.0
    assert abs(np.linalg.norm(rp - (a + t * (b - a))) - radius) <= 0.003  # (each number rounded to 0.5 mm)
    assert abs(np.linalg.norm(hp - rp) - max(hit.d_HR, 0.0)) <= 0.003
    # the first step each device sees the worker
    assert ep["first_seen"][view.records[view.detection_row].devices[0]] == view.detection_row


def test_reach_nodes_kept_are_the_kernels(s3_witness_view) -> None:
    """Near a fence the kernel's detour test drops reach nodes; the mask sent to the page keeps exactly the
    points ``scene.reach_points`` returns."""
    view = s3_witness_view
    layout = view.layout
    nodes = scene.reach_nodes(layout, 4)
    cut = 0
    for i in range(len(view.records)):
        pose = view.pose(i)
        for side in (0, 1):
            keep = reach_kept(layout, pose, side, nodes, 4)
            pts = scene.reach_points(layout, pose, side, 4, nodes)
            assert keep.sum() == len(pts)
            local = nodes[keep].copy()
            if side == 0:
                local[:, 1] = -local[:, 1]
            assert np.abs(pose.shoulders[side] + local @ pose.trunk.T - pts).max() < 1e-9
            cut += int((~keep).sum())
    assert cut > 0  # S3 reaches past a fence: the test saw nodes dropped


class _Tags(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def test_report_is_self_contained_and_deterministic(s3_report, tmp_path) -> None:
    from cellstress.report import write_report

    raw = (s3_report / "report.html").read_text(encoding="utf-8")
    p = _Tags()
    p.feed(raw)
    scripts = [a for t, a in p.tags if t == "script"]
    assert len(scripts) == 3 and all("src" not in a for a in scripts)
    # outside the inline scripts (plotly.js names sites in its sources and licences) the page names no URL
    markup = re.sub(r"<script\b.*?</script>", "", raw, flags=re.S)
    assert "http:" not in markup and "https:" not in markup and "url(" not in markup
    assert _data(raw)["episodes"][0]["marker"]["kind"] == "contact"
    write_report(s3_report / "result.json", tmp_path)
    assert (tmp_path / "report.html").read_bytes() == (s3_report / "report.html").read_bytes()
    assert len(raw.encode()) <= SIZE_BUDGET


def test_json_cannot_end_its_script(s1_witness_view) -> None:
    data = ViewData({"name": "</script><script>alert(1)</script> & <!--"}, None, ())
    text = data.to_json()
    assert "<" not in text and ">" not in text and "&" not in text
    assert json.loads(text)["cell"]["name"] == "</script><script>alert(1)</script> & <!--"


def test_size_budget_sixteen_actions_two_robots(tmp_path) -> None:
    """The budget's case: a 16-action episode in a cell of two robots, with the paper worker's reach volumes."""
    from importlib import resources

    import yaml

    from cellstress.cell.load import load_cell
    from cellstress.report.episode import replay
    from cellstress.sim.simulator import Simulator

    doc = yaml.safe_load(resources.files("cellstress.cell.builtin").joinpath("two-robots-fixed.yaml")
                         .read_text(encoding="utf-8"))
    doc["simulation"] = {**doc.get("simulation", {}), "actions_per_episode": 16}
    path = tmp_path / "two16.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    sim = Simulator(load_cell(str(path)))
    actions = ["turn-left-45+upright", "turn-right-45+bend-forward"] * 8  # in place: the episode runs to its end
    view = replay(sim, actions, episode=1, kind="riskiest")
    assert len(view.actions) == 16 and len(sim.layout.robots) == 2
    html = view_fragment(view_of_episodes(view.layout, [(view, "16 actions")]))
    assert len(html.encode()) <= SIZE_BUDGET
    doc = _data(html)
    assert len(doc["episodes"][0]["robot"]) == 16 * sim.steps_per_action + 1
