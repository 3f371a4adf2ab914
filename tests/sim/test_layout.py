"""sim.layout: every integer the kernels index with is its spec's index of that name, and the specs say what
the rest of the code assumes of them."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.core.vector_spec import VectorSpec
from cellstress.human.body import BODY_PARTS, BodyDimensions
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.records import STOP_PHASES

SPECS = {"S_": L.STATE, "M_": L.ROW, "PHASE_": L.PHASE, "C_": L.SCALARS, "B_": L.BODY_PARAMS, "DEV_": L.DEVICE_KINDS}


@pytest.mark.parametrize("prefix", sorted(SPECS))
def test_every_constant_is_its_slot_index(prefix):
    spec = SPECS[prefix]
    consts = {n[len(prefix):]: getattr(L, n) for n in dir(L) if n.startswith(prefix) and n[len(prefix):] in spec.names}
    assert consts == {n: i for i, n in enumerate(spec.names)}


def test_sizes_and_what_the_code_assumes():
    assert (L.NS, L.NM, L.N_SCAL, L.N_BODY_PARAMS) == (L.STATE.size, L.ROW.size, L.SCALARS.size, L.BODY_PARAMS.size)
    # the rows' points are read as slices (row[M_RX:M_RZ + 1])
    assert (L.M_RY, L.M_RZ) == (L.M_RX + 1, L.M_RX + 2) and (L.M_HY, L.M_HZ) == (L.M_HX + 1, L.M_HX + 2)
    assert len(STOP_PHASES) == L.PHASE.size
    assert BODY_PARTS[L.PART_LEFT_REACH:L.PART_RIGHT_REACH + 1] == ("left-reach", "right-reach")
    assert L.N_BODY_CAPSULES == L.PART_LEFT_REACH
    assert BodyDimensions(1.75, 0.3, 0.27, 0.19, 1.6).params().shape == (L.N_BODY_PARAMS,)
    assert all(m for _, m in L.STATE.slots + L.ROW.slots + L.SCALARS.slots + L.BODY_PARAMS.slots)


def test_the_kernels_do_not_hand_out_the_layout():
    """Callers read the layout from sim.layout alone (the kernels package exports only kernels)."""
    assert not [n for n in K.__all__ if n.isupper() and n != "TRACE_REL_TOL"]
    assert not hasattr(K, "M_D") and not hasattr(K, "S_X")


def test_vector_spec_refuses_a_forgotten_or_doubled_slot():
    spec = VectorSpec("v", (("A", "a"), ("B", "b")))
    assert spec.indices("B", "A") == (1, 0)
    assert spec.meaning("B") == "b" and "| 1 | B | b |" in spec.table()
    with pytest.raises(ValueError, match="missing"):
        spec.indices("A")
    with pytest.raises(ValueError):
        spec.indices("A", "B", "B")
    with pytest.raises(KeyError):
        spec.index("C")
    with pytest.raises(ValueError, match="twice"):
        VectorSpec("w", (("A", "a"), ("A", "b")))


def test_a_state_is_laid_out_as_described(baseline_sim):
    s = baseline_sim.reset()
    assert s.shape == (L.NS,) and s[L.S_TSTOP] == np.inf and s[L.S_TRIG_DEV] == -1.0
    assert tuple(s[[L.S_X, L.S_Y]]) == tuple(baseline_sim.start[:2])
