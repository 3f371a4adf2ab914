"""What a verdict covers, said once: the worker model, the horizon against the cell's own, the start points,
the arrival moments, and every approximation with its size (``records.Scope``). The command line, verify.html
and verify.json all show this record, so no message claims more than the run decided."""

from __future__ import annotations

from cellstress.sim import layout as L
from cellstress.sim.kernels.sweep import flag_distance
from cellstress.verifier.arrival import ArrivalCover
from cellstress.verifier.records import Approximation, Scope, VerifyOptions


def _between_steps(sim, dt: float) -> Approximation:
    """How contact between the time steps is tested (``kernels.sweep``)."""
    P = sim.params
    if P.scal[L.C_SWEEP] == 0.0:
        return Approximation(name="time step", size=dt, unit="s",
                             what="contact is tested at every time step only; a contact that begins and ends "
                                  "between two steps is not seen")
    margin = flag_distance(P) - float(P.scal[L.C_DTOL])
    return Approximation(name="between steps", size=margin, unit="m",
                         what=f"contact is tested in continuous time between the {dt:g} s steps (the worker on the "
                              "straight line between its sampled poses, the robot on its path); where it cannot be "
                              "ruled out within 1/32 of a step it counts, so a pass this much closer than the "
                              "contact distance may count as a contact (never a miss)")


def arrival_text(options: VerifyOptions, cover: ArrivalCover, grid: bool, phases: tuple[float, ...],
                 cycle: float, dt: float) -> tuple[str, bool]:
    """(how the arrival moments are covered, whether the moments between grid points are)."""
    if not grid:
        moments = ", ".join(f"{p:g} s" for p in phases[:6]) + (", ..." if len(phases) > 6 else "")
        return f"the cell's fixed arrival moment{'s' if len(phases) > 1 else ''} only ({moments})", False
    if options.phases == "all":
        span = f"{len(phases)} grid moments {dt:g} s apart over the robot's {cycle:g} s cycle"
    elif options.phases == "window":
        a, b = options.window
        span = f"{len(phases)} grid moments {dt:g} s apart from {a:g} to {b:g} s of the robot's {cycle:g} s cycle"
    else:
        span = f"{len(phases)} grid moments {dt:g} s apart in the cell's arrival window"
    if options.moments == "grid":
        return f"the {span} only (--moments grid)", False
    if not cover.covered:
        return f"the {span} only: moments between them are not covered because {cover.reason}", False
    return (f"every arrival moment within {cover.half_window:g} s of the {span} (robot capsules grown by up to "
            f"{cover.largest * 1000:.0f} mm for the moments between)"), True


def build_scope(sim, options: VerifyOptions, cover: ArrivalCover, grid: bool, starts: tuple[str, ...],
                phases: tuple[float, ...]) -> Scope:
    """The scope of a verification of ``sim``'s cell with ``options`` (see the module)."""
    cell = sim.cell
    worker = cell.spec.human.model
    n_actions = len(sim.action_names)
    own = int(sim.actions_per_episode)
    dt = float(sim.dt)
    cycle = float(sim.layout.trajectory.cycle)
    arrival, between = arrival_text(options, cover, grid, phases, cycle, dt)
    approx = [
        _between_steps(sim, dt),
        Approximation(name="merging", size=0.0, unit="m",
                      what="none: states merge only when every slot that decides the future is equal bit for bit"),
        Approximation(name="reach field", size=float(sim.params.scal[L.C_REACH_H]), unit="m",
                      what="the arm's reach volume is a distance field on a grid of this spacing, interpolated; "
                           "its nearest point to a robot capsule is found to within one spacing"),
    ]
    if between:
        approx.append(Approximation(name="arrival window", size=cover.largest, unit="m",
                                    what=f"arrivals between grid moments are covered by growing each robot capsule by "
                                         f"how far it moves in {cover.half_window:g} s; its alarms are replayed "
                                         "across the window and reported apart"))
    if options.horizon < own:
        approx.append(Approximation(name="horizon", size=float(options.horizon), unit="actions",
                                    what=f"episodes of {options.horizon} actions, shorter than the cell's own "
                                         f"{own}: later contacts are not decided"))
    who = f"the {worker} worker ({n_actions} actions per decision, {options.horizon} per episode"
    who += ")" if options.horizon >= own else f"; the cell's episodes have {own})"
    statement = (f"The verdict is about the model: {who}, body and walking speed as the cell gives them; start "
                 f"point{'s' if len(starts) > 1 else ''} {', '.join(starts)}; {arrival}; the robot's program and "
                 f"stopping as the cell gives them; contacts tested every {dt:g} s; the criterion "
                 f"{cell.spec.criterion.type}. It says nothing of workers who move otherwise, faster or longer, of "
                 "sensor faults, or of what the simulator does not model.")
    return Scope(worker=worker, actions=n_actions, horizon=options.horizon, cell_horizon=own, starts=starts,
                 arrival=arrival, margin=cover.largest if between else 0.0, approximations=tuple(approx),
                 statement=statement)
