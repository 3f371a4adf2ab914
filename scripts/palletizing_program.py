"""Write the built-in palletizing cell's robot program as a joint-trajectory file, as an offline-programming tool
would export it: src/cellstress/cell/builtin/palletizing.csv.

    python scripts/palletizing_program.py [--check]

The Panda (fingers held 4 cm apart) stands on a 0.6 m pedestal at the origin. Each cycle it picks a box at the
conveyor's end and places it on the pallet, twice, at two places of the layer:

* vertical approach and retreat (0.15 m) are straight lines of the hand, solved by inverse kinematics every
  20 ms along a minimum-jerk profile, as a controller's linear moves;
* the transfers between the pick and the place are joint-space minimum-jerk moves at half the joint speed
  limits, as point-to-point moves;
* the gripper closes and opens during a 0.3 s dwell.

``--check`` recomputes the file and fails if the committed one differs (the file is data: it is regenerated,
not edited by hand).
"""

from __future__ import annotations

import argparse
import io
import sys
from pathlib import Path

import numpy as np
import yaml

from cellstress.cell.program import _pose_matrix
from cellstress.robot.ik import solve_poses
from cellstress.robot.joints import JointMap
from cellstress.robot.model import base_matrix, load_robot, resolve_urdf

BUILTIN = Path(__file__).resolve().parents[1] / "src/cellstress/cell/builtin"
OUT = BUILTIN / "palletizing.csv"
CELL = BUILTIN / "palletizing.yaml"
DT = 0.02  # s between rows
LIFT = 0.15  # m, vertical approach and retreat
GRIP = 0.3  # s, the gripper's dwell at pick and place
SPEED = 0.5  # share of the joint speed limits on transfers
PICK = (0.0, -0.55, 1.0)  # hand frame at the box on the conveyor's end [m]
PLACES = ((0.55, 0.22, 0.5), (0.55, -0.22, 0.5))  # hand frame at the two places on the pallet's layer [m]


READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])  # Franka's "ready" pose [rad]


def hand_down(p) -> tuple[float, float, float]:
    """rpy [deg] of the hand over point p: fingers down, turned with the arm (as in the ready pose)."""
    return (180.0, 0.0, float(np.degrees(np.arctan2(p[1], p[0]))))


def min_jerk(u: np.ndarray) -> np.ndarray:
    return u ** 3 * (10 - 15 * u + 6 * u * u)


def linear(jmap, to_base, a, b, duration: float, seed) -> np.ndarray:
    """Hand moving straight from a to b (cell frame) in ``duration`` s: joint rows every DT (a excluded)."""
    n = max(2, int(round(duration / DT)))
    s = min_jerk(np.arange(1, n + 1) / n)
    targets = [to_base @ _pose_matrix(np.asarray(a) + si * (np.asarray(b) - np.asarray(a)), hand_down(a)) for si in s]
    return solve_poses(jmap, "panda_hand", targets, seed)


def transfer(q0: np.ndarray, q1: np.ndarray, vmax: np.ndarray) -> np.ndarray:
    """Joint-space minimum-jerk move from q0 to q1 at SPEED of the speed limits: rows every DT (q0 excluded)."""
    t = max(0.4, float(np.max(1.875 * np.abs(q1 - q0) / (SPEED * vmax))))
    n = int(np.ceil(t / DT))
    s = min_jerk(np.arange(1, n + 1) / n)
    return q0 + s[:, None] * (q1 - q0)


def hold(q: np.ndarray, duration: float) -> np.ndarray:
    return np.repeat(q[None, :], int(round(duration / DT)), axis=0)


def program() -> tuple[tuple[str, ...], np.ndarray]:
    # the robot as the cell file places it (read as plain YAML: the cell cannot load before its program exists)
    spec = yaml.safe_load(CELL.read_text())["robot"]
    robot = load_robot(resolve_urdf(spec["urdf"], None))
    held = {robot.joint_names.index(h["joint"]): float(h["value"]) for h in spec.get("hold", ())}
    driven = [j for j in range(robot.n_joints) if j not in held and robot.mimic_master[j] < 0]
    jmap = JointMap(robot, tuple(driven), held)
    to_base = np.linalg.inv(base_matrix(spec["base"]["xyz"], spec["base"].get("yaw_deg", 0.0)))
    vmax = robot.velocity_limits[driven]
    seed = READY.copy()
    seed[0] = np.arctan2(PICK[1], PICK[0])  # the ready pose turned towards the conveyor

    def above(p):
        return (p[0], p[1], p[2] + LIFT)

    q_pick_up = solve_poses(jmap, "panda_hand", [to_base @ _pose_matrix(above(PICK), hand_down(PICK))], seed)[0]
    rows = [q_pick_up[None, :]]
    q = q_pick_up
    for place in PLACES:
        down = linear(jmap, to_base, above(PICK), PICK, 0.6, q)
        up = linear(jmap, to_base, PICK, above(PICK), 0.6, down[-1])
        rows += [down, hold(down[-1], GRIP), up]
        q_place_up = solve_poses(jmap, "panda_hand", [to_base @ _pose_matrix(above(place), hand_down(place))],
                                 up[-1])[0]
        rows.append(transfer(up[-1], q_place_up, vmax))
        down = linear(jmap, to_base, above(place), place, 0.6, q_place_up)
        up = linear(jmap, to_base, place, above(place), 0.6, down[-1])
        rows += [down, hold(down[-1], GRIP), up, transfer(up[-1], q_pick_up, vmax)]
        q = q_pick_up
    q_all = np.concatenate(rows)
    q_all[-1] = q_all[0]  # the file's last row repeats its first: the cycle closes exactly
    return tuple(robot.joint_names[j] for j in driven), q_all


def text() -> str:
    names, q = program()
    buf = io.StringIO()
    buf.write("time," + ",".join(names) + "\n")
    for i, row in enumerate(q):
        buf.write(f"{i * DT:.2f}," + ",".join(f"{v:.6f}" for v in row) + "\n")
    return buf.getvalue()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    new = text()
    if args.check:
        same = OUT.is_file() and OUT.read_text() == new
        print("palletizing.csv is up to date" if same else "palletizing.csv differs: run the script")
        return 0 if same else 1
    OUT.write_text(new)
    print(f"wrote {OUT} ({new.count(chr(10)) - 1} rows)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
