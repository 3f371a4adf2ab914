"""scripts/kernel_reference.py's ``compare``: what it reports for two recordings, on small synthetic ones."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from cellstress.sim import layout as L

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "kernel_reference.py"


def load_script():
    spec = importlib.util.spec_from_file_location("kernel_reference", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def recording(mod, seed: int = 0) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    out = {}
    for c in mod.CELLS:
        out[f"{c}:d_end"] = rng.uniform(0.1, 2.0, size=(20, 8))
        out[f"{c}:unsafe_step"] = np.full(20, -1)
        for name, n in (("run", 200), ("step", 300)):
            for i in range(n):
                rows = np.zeros((3, L.NM))
                rows[:, L.M_D] = rng.uniform(0.1, 2.0, size=3)
                out[f"{c}:{name}{i}"] = rows
    return out


def test_compare_reports_moves_and_outcome_changes(capsys):
    mod = load_script()
    old = recording(mod)
    assert mod.compare(old, {k: v.copy() for k, v in old.items()}) == 0
    text = capsys.readouterr().out
    assert text.count("unsafe episodes same") == len(mod.CELLS)
    assert "d_end moved in 0 of 160" in text and "closest link/part changed in 0" in text

    new = {k: v.copy() for k, v in old.items()}
    cell = mod.CELLS[-1]
    new[f"{cell}:d_end"][3, 2] += 0.004  # a 4 mm move, far from contact
    new[f"{cell}:run7"][1, L.M_D] = 0.03  # a trace row moved to within 5 cm of contact
    new[f"{cell}:step9"][0, L.M_PART] = 2.0  # another closest body part
    assert mod.compare(old, new) == 0  # unsafe outcomes unchanged
    line = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith(cell)][0]
    assert "d_end moved in 1 of 160 (max 4.00e-03 m" in line
    assert "within 5 cm of contact 1" in line and "closest link/part changed in 1" in line

    new[f"{cell}:unsafe_step"][5] = 17
    assert mod.compare(old, new) == 1
    assert f"{cell}: unsafe episodes DIFFER (1 of 20)" in capsys.readouterr().out
