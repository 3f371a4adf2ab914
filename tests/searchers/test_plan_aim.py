"""``plan``'s aim (``Plan.aim``, used by ``check --witness``): read strictly, and the point it gives the model is
on the robot at the steps the model puts it, with the arrival phase fixed or searched."""

from __future__ import annotations

import numpy as np
import pytest

from cellstress.searchers import SearchError, search
from cellstress.searchers.multistart import PhaseProblem
from cellstress.searchers.plan import Aim, Plan, _Model
from cellstress.sim import kernels as K
from cellstress.sim import layout as L
from cellstress.sim.simulator import Simulator


@pytest.mark.parametrize("aim", ["1,2,3", "1,2,3,4,5,6", "a,1,2,3", "nan,0,0,1", "1,0,0,inf", "-1,0,0,1",
                                 "1,0,0,1,0.5", "1,0,0,1,-1", 1.5])
def test_bad_aims(aim) -> None:
    with pytest.raises(SearchError):
        Plan(aim=aim)


def test_aim_read() -> None:
    assert Plan().aimed() is None and Plan(aim=" ").aimed() is None
    assert Plan(aim="1.46,0.79,0.75,1.09").aimed() == Aim(0, 1.46, (0.79, 0.75, 1.09))
    assert Plan(aim="1,0,0,1,2").aimed().robot == 2


def test_aim_names_a_robot_the_cell_has() -> None:
    with pytest.raises(SearchError, match="robot 1; the cell has 1"):
        search(Simulator("s3-fence-gap"), "plan", 5, 0, aim="1.0,0,0,1,1")


def _surface_gap(P, t: float, point, c: int) -> float:
    """Distance from ``point`` to the surface of robot 0's capsule c at episode time t (the kernel poses it)."""
    W = K.make_work(P)
    K.robot_live(P, float(t), np.inf, W)
    p, a, b = np.asarray(point), W.ra[c], W.rb[c]
    s = float(np.clip(np.dot(p - a, b - a) / max(float(np.dot(b - a, b - a)), 1e-18), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + s * (b - a))) - P.cap_r[c])


@pytest.mark.parametrize("cell", ["s3-fence-gap", "palletizing"])
def test_aimed_steps_are_where_the_robot_is(cell) -> None:
    """The model holds the aimed point at the steps whose moment is the aim's (modulo the cycle), and there only;
    the robot, posed by the kernel at such a step's own time, passes through the point (up to what it moves in
    the half step between); half a cycle on it does not. palletizing searches its arrival phase: its path
    steps count from phase 0 of the cycle, not the cell's phase."""
    sim = Simulator(cell)
    P = sim.params
    dt, cycle, phase0 = float(P.scal[L.C_DT]), float(P.scal[L.C_CYCLE]), float(P.scal[L.C_PHASE0])
    problem = PhaseProblem(sim) if cell == "palletizing" else sim
    lead = 1 if cell == "palletizing" else 0
    t_aim = 1.23
    W = K.make_work(P)
    K.robot_live(P, t_aim, np.inf, W)
    c = P.cap_joint.shape[0] - 1  # the last capsule (the tool's end of the arm: it moves most)
    a, b, r = W.ra[c], W.rb[c], float(P.cap_r[c])
    side = np.cross(b - a, [0.0, 0.0, 1.0])
    point = 0.5 * (a + b) + r * side / np.linalg.norm(side)  # on its surface at t_aim
    assert abs(_surface_gap(P, t_aim, point, c)) < 1e-9
    model = _Model(problem, lead)
    model.know(Aim(0, t_aim, tuple(point)))
    steps = [k for k, found in enumerate(model.points[0]) if found]
    assert steps
    # how fast the capsule's surface moves past the point (at most), sampled every 10 ms around the aim
    gaps = [_surface_gap(P, t, point, c) for t in np.arange(t_aim - 0.1, t_aim + 0.1, 0.005)]
    speed = float(np.max(np.abs(np.diff(gaps)))) / 0.005
    for k in steps:
        t = k * dt - (phase0 if lead else 0.0)  # the step's episode time from the cell's phase
        lag = (t - t_aim + 0.5 * cycle) % cycle - 0.5 * cycle
        assert abs(lag) <= 0.5 * dt + 1e-9
        assert model.speed[0][k] == np.inf
        assert _surface_gap(P, t, point, c) <= speed * 0.5 * dt + 1e-6
    # every step whose moment is the aim's has it
    n_path = len(model.points[0])
    origin = phase0 if lead else 0.0
    expected = [k for k in range(n_path)
                if abs((k * dt - origin - t_aim + 0.5 * cycle) % cycle - 0.5 * cycle) <= 0.5 * dt + 1e-9]
    assert steps == expected
    if lead == 0:
        assert _surface_gap(P, t_aim + 0.5 * cycle, point, c) > 0.01  # half a cycle on, the robot is elsewhere


def test_aim_is_part_of_the_result_and_deterministic(tmp_path) -> None:
    sim = Simulator("s3-fence-gap")
    aim = "1.4600,0.7927,0.7466,1.0887"
    a = search(sim, "plan", 50, 3, aim=aim)
    b = search(sim, "plan", 50, 3, aim=aim)
    assert a.params["aim"] == aim and a.to_json() == b.to_json()
