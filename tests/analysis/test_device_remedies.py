"""analysis.device_remedies: candidates that change a safeguard's settings or outline, or add one; each on a
one-line variant of a built-in cell, each checked to make its row pass (and the step below it to fail, where
the candidate was found by bisection or re-measuring). The re-test is ``fix``'s (tests/cli/test_fix_cli.py)."""

from __future__ import annotations

from pathlib import Path

import yaml

from cellstress.analysis.device_remedies import (
    SPEED_STEP,
    covered_gaps,
    deeper_mats,
    enlarged_warnings,
    finer_resolutions,
    reduced_speeds,
)
from cellstress.analysis.fix import _moves, _static_of, checked
from cellstress.cell.load import builtin_file, load_cell, parse_cell
from cellstress.core.iso13855 import MAT_MIN_DEPTH_MM, min_scan_height_mm


def _cell_of(text, tmp_path, name="candidate.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return parse_cell(text, str(path), tmp_path)


def _variant(cell, old, new, tmp_path):
    text = Path(builtin_file(cell)).read_text()
    assert text.count(old) == 1, old
    return _cell_of(text.replace(old, new), tmp_path, f"{cell}-variant.yaml")


def _static_fn(cell, tmp_path):
    return lambda text: _static_of(cell, text, tmp_path / "scratch.yaml")


def _scanner(text):
    return next(d for d in yaml.safe_load(text)["devices"] if d["type"] == "laser-scanner")


WARNING_FRONT = "polygon: [[-1.5, 3.6], [1.5, 3.6]"


def test_a_short_warning_field_is_grown_until_its_row_passes(tmp_path):
    """warning-field-ok with its warning field's front edge pulled in to y = 3.3: only the warning row fails; the
    candidate moves the warning field's front edge out (the protective field stays) and every row passes."""
    cell = _variant("warning-field-ok", WARNING_FRONT, "polygon: [[-1.5, 3.3], [1.5, 3.3]", tmp_path)
    before, static = checked(cell)
    assert before.failing == ("front-scanner:warning",)
    (r,) = enlarged_warnings(cell, static, _static_fn(cell, tmp_path))
    assert r.kind == "warning-field" and r.parts_added == 0 and r.rows == ("front-scanner:warning",)
    after = _scanner(r.text)
    assert after["polygon"] == _scanner(Path(cell.source).read_text())["polygon"]
    assert max(p[1] for p in after["warning"]["polygon"]) > 3.3
    assert checked(_cell_of(r.text, tmp_path))[0].failing == ()


def test_a_protective_field_a_little_short_gets_a_lower_reduced_speed(tmp_path):
    """warning-field-ok with the protective front edge at 2.8 instead of 2.9: the reduced speed is lowered to the
    largest step at which the protective row passes; one step above it fails."""
    cell = _variant("warning-field-ok", "polygon: [[-1.5, 2.9], [1.5, 2.9]", "polygon: [[-1.5, 2.8], [1.5, 2.8]",
                    tmp_path)
    before, static = checked(cell)
    assert before.failing == ("front-scanner",)
    (r,) = reduced_speeds(cell, static, _static_fn(cell, tmp_path))
    speed = _scanner(r.text)["warning"]["reduced_speed"]
    assert r.kind == "reduced-speed" and 0.0 < speed < 0.25
    assert checked(_cell_of(r.text, tmp_path))[0].failing == ()
    above = r.text.replace(f"reduced_speed: {speed}", f"reduced_speed: {round(speed + SPEED_STEP, 6)}")
    assert above != r.text and "front-scanner" in checked(_cell_of(above, tmp_path, "above.yaml"))[0].failing


def test_a_scanner_without_a_warning_field_gets_a_reduced_speed_zone(tmp_path):
    """The baseline's scanner with a quicker response (0.1 s, so that the robot's stopping time weighs) and its
    front edge pulled in to y = 2.45, short of the full-speed distance but not of the one at a reduced speed: a
    warning field is added around the protective field, and its own row passes too."""
    quick = "    height: 0.3\n    response_time: 0.1\n"
    cell = _variant("baseline", "    height: 0.3\n    response_time: 0.35\n", quick, tmp_path)
    front = "polygon: [[-1.5, 3.2], [1.5, 3.2]"
    text = Path(cell.source).read_text().replace(front, front.replace("3.2", "2.45"))
    cell = _cell_of(text, tmp_path, "short.yaml")
    before, static = checked(cell)
    assert "front-scanner" in before.failing
    (r,) = reduced_speeds(cell, static, _static_fn(cell, tmp_path))
    warning = _scanner(r.text)["warning"]
    assert r.kind == "reduced-speed" and "reduced-speed zone" in r.change and 0.0 < warning["reduced_speed"] < 1.0
    assert checked(_cell_of(r.text, tmp_path))[0].failing == ()


def test_a_scanner_too_coarse_for_its_height_gets_the_coarsest_resolution_that_fits(tmp_path):
    """The baseline's scanner given a 150 mm resolution at 300 mm: 15 (d - 50) <= 300 allows d <= 70 mm."""
    cell = _variant("baseline", "    height: 0.3\n    response_time: 0.35\n",
                    "    height: 0.3\n    response_time: 0.35\n    resolution_mm: 150\n", tmp_path)
    before, static = checked(cell)
    assert "front-scanner-mounting" in before.failing
    (r,) = finer_resolutions(cell, static)
    d = _scanner(r.text)["resolution_mm"]
    assert r.kind == "scanner-resolution" and d == 70.0
    assert min_scan_height_mm(d) <= 300.0 < min_scan_height_mm(d + 10.0)
    assert "front-scanner-mounting" not in checked(_cell_of(r.text, tmp_path))[0].failing


def test_a_shallow_mat_is_deepened_to_the_minimum(tmp_path):
    """mat-ok's mat cut to a 0.5 m strip at the front: its depth row fails; the candidate moves the edge the
    shallowest crossing starts from outward, and the depth row passes."""
    old = ("polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, -0.4], [1.0, -0.4], [1.0, 1.2], [0.45, 1.2], [0.45, 0.3],\n"
           "              [-0.45, 0.3], [-0.45, 1.2], [-1.0, 1.2], [-1.0, -0.4], [-1.5, -0.4]]")
    cell = _variant("mat-ok", old, "polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, 2.7], [-1.5, 2.7]]", tmp_path)
    before, static = checked(cell)
    assert "front-mat-depth" in before.failing
    (r,) = deeper_mats(cell, static)
    mat = next(d for d in yaml.safe_load(r.text)["devices"] if d["name"] == "front-mat")
    ys = [p[1] for p in mat["polygon"]]
    assert r.kind == "mat-depth" and (max(ys) - min(ys)) * 1000.0 >= MAT_MIN_DEPTH_MM
    assert "front-mat-depth" not in checked(_cell_of(r.text, tmp_path))[0].failing


def test_a_gap_nobody_sees_gets_a_curtain_across_it(tmp_path):
    """s3-fence-gap with the scanner's right aisle cut off at y = 1.0: the aisle from the right wall's free end to
    the table admits the body unseen; the candidate puts a light curtain across it (one part) as high as the
    wall, and the opening is covered (the curtain's own ISO 13855 row is check's to judge, as any device's)."""
    old = "polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, -0.4], [1.0, -0.4], [1.0, 1.2]"
    cell = _variant("s3-fence-gap", old, "polygon: [[-1.5, 3.2], [1.5, 3.2], [1.5, 1.0], [1.0, 1.0], [1.0, 1.2]",
                    tmp_path)
    before, static = checked(cell)
    assert "whole-body-opening" in before.failing
    found = covered_gaps(cell, static)
    assert found
    for r in found:
        new = [d for d in yaml.safe_load(r.text)["devices"] if d["type"] == "light-curtain"][-1]
        assert r.kind == "cover-gap" and r.parts_added == 1 and new["name"].startswith("gap-curtain-")
        assert new["top"] == 2.0 and new["bottom"] <= 0.3
    assert any("whole-body-opening" not in checked(_cell_of(r.text, tmp_path, f"c{k}.yaml"))[0].failing
               for k, r in enumerate(found))


def test_cells_whose_rows_pass_get_none_of_these():
    for name in ("baseline", "warning-field-ok", "mat-ok"):
        cell = load_cell(name)
        _, static = checked(cell)
        assert not (finer_resolutions(cell, static) + deeper_mats(cell, static) + covered_gaps(cell, static))
        assert not enlarged_warnings(cell, static, lambda t: None) and not reduced_speeds(cell, static,
                                                                                           lambda t: None)


def test_a_warning_field_that_lets_the_robot_run_too_fast_gets_a_lower_reduced_speed(tmp_path):
    """warning-field-ok with a speed limit of 0.2 m/s near the protective field: at 0.25 of its path speed the
    robot runs faster there; the reduced speed is lowered until it does not, and the warning row stays green."""
    cell = _variant("warning-field-ok", "      reduced_speed: 0.25\n",
                    "      reduced_speed: 0.25\n      speed_limit: 0.2\n", tmp_path)
    before, static = checked(cell)
    assert before.failing == ("front-scanner:warning-speed",)
    (r,) = reduced_speeds(cell, static, _static_fn(cell, tmp_path))
    assert r.rows == ("front-scanner:warning-speed",)
    speed = _scanner(r.text)["warning"]["reduced_speed"]
    assert 0.0 < speed < 0.25
    assert checked(_cell_of(r.text, tmp_path))[0].failing == ()
    above = r.text.replace(f"reduced_speed: {speed}", f"reduced_speed: {round(speed + SPEED_STEP, 6)}")
    assert "front-scanner:warning-speed" in checked(_cell_of(above, tmp_path, "above.yaml"))[0].failing


def test_a_warning_row_gets_no_move_of_the_device_alone(tmp_path):
    """The warning row names no device of the file: moving 'the device alone' would move nothing (it once gave
    a candidate that repeated the same empty move four times); the move with the cell still stretches it."""
    cell = _variant("warning-field-ok", WARNING_FRONT, "polygon: [[-1.5, 3.3], [1.5, 3.3]", tmp_path)
    _, static = checked(cell)
    assert _moves(cell, static, False, tmp_path / "scratch.yaml") == ()
    (m,) = _moves(cell, static, True, tmp_path / "scratch.yaml")
    assert m.device == "front-scanner:warning" and m.delta > 0.0
