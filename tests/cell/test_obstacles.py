"""Obstacles in the cell file: footprints (polygon or box), names, and start points kept off them."""

from __future__ import annotations

import math
from importlib import resources

import pytest
import yaml

from cellstress.cell.load import parse_cell
from cellstress.core.errors import CellError


@pytest.fixture(scope="module")
def baseline() -> dict:
    text = resources.files("cellstress.cell").joinpath("builtin", "baseline.yaml").read_text(encoding="utf-8")
    return yaml.safe_load(text)


def _cell(data: dict, tmp_path):
    return parse_cell(yaml.safe_dump(data), str(tmp_path / "cell.yaml"), tmp_path)


def test_box_and_polygon_footprints(baseline, tmp_path):
    data = dict(baseline, obstacles=[
        {"name": "conveyor", "box": {"center": [2.0, 2.0], "size": [2.0, 0.5], "yaw_deg": 90.0}, "height": 0.9},
        {"name": "pallet", "polygon": [[-2.4, 3.5], [-1.6, 3.5], [-1.6, 4.1], [-2.4, 4.1]], "height": 0.15},
    ])
    spec = _cell(data, tmp_path).spec
    names = [o.name for o in spec.solid_obstacles()]
    assert names == ["table", "conveyor", "pallet"]
    corners = spec.obstacles[0].footprint()
    # rotated by 90 deg: 0.5 m along x, 2 m along y, centred on (2, 2)
    xs, ys = sorted(c[0] for c in corners), sorted(c[1] for c in corners)
    assert math.isclose(xs[0], 1.75, abs_tol=1e-12) and math.isclose(xs[-1], 2.25, abs_tol=1e-12)
    assert math.isclose(ys[0], 1.0, abs_tol=1e-12) and math.isclose(ys[-1], 3.0, abs_tol=1e-12)
    assert spec.obstacles[1].footprint() == tuple(tuple(p) for p in data["obstacles"][1]["polygon"])


@pytest.mark.parametrize("obstacles, words", [
    ([{"name": "a", "height": 1.0}], "exactly one of polygon and box"),
    ([{"name": "a", "height": 1.0, "box": {"center": [0, 0], "size": [1, 1]},
       "polygon": [[0, 0], [1, 0], [1, 1]]}], "exactly one of polygon and box"),
    ([{"name": "a", "height": 1.0, "box": {"center": [3, 3], "size": [0.2, 0.2]}},
      {"name": "a", "height": 1.0, "box": {"center": [-3, 3], "size": [0.2, 0.2]}}], "unique"),
    ([{"name": "table", "height": 1.0, "box": {"center": [2, -2], "size": [0.2, 0.2]}}], "table"),
    ([{"name": "a", "height": 0.0, "box": {"center": [2, -2], "size": [0.2, 0.2]}}], "height"),
    ([{"name": "a", "height": 1.0, "box": {"center": [2, -2], "size": [-1, 0.2]}}], "size"),
])
def test_bad_obstacles_are_one_clear_error(baseline, tmp_path, obstacles, words):
    with pytest.raises(CellError) as err:
        _cell(dict(baseline, obstacles=obstacles), tmp_path)
    assert words in str(err.value)
    assert "obstacles" in str(err.value)


def test_start_inside_an_obstacle_is_refused(baseline, tmp_path):
    x, y = baseline["human"]["start"]["xy"]
    data = dict(baseline, obstacles=[{"name": "crate", "box": {"center": [x, y], "size": [0.4, 0.4]}, "height": 0.5}])
    with pytest.raises(CellError) as err:
        _cell(data, tmp_path)
    assert "'crate'" in str(err.value) and "human.start.xy" in str(err.value)


def test_a_cell_needs_no_table(baseline, tmp_path):
    data = {k: v for k, v in baseline.items() if k != "table"}
    spec = _cell(data, tmp_path).spec
    assert spec.table is None and spec.solid_obstacles() == ()
