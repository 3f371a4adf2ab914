"""``cellstress simulate``: play one action sequence and print every 50 ms step."""

from __future__ import annotations

import json
from typing import Annotated

import typer

from cellstress.cli.common import (
    CELL_HELP,
    HEADER,
    check_criterion,
    criterion_help,
    num,
    say,
    spinner_while_compiling,
    step_line,
    user_errors,
)


def simulate(
    cell: Annotated[str, typer.Argument(help=CELL_HELP)],
    actions: Annotated[str, typer.Option("--actions", "-a", help="Comma-separated actions, e.g. "
                                         "walk+upright,turn-left-45+bend-forward (WALK+BODY).")],
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON document instead of the table.")] \
        = False,
    criterion: Annotated[str | None, typer.Option("--criterion", help=criterion_help("the cell file's"))] = None,
) -> None:
    """Play a sequence of worker actions in a cell and report whether it ends in an unsafe contact.

    Exit code 0 if the episode stays safe, 1 if it ends unsafe, 2 for a bad cell or action."""
    from cellstress.cell.load import load_cell, with_criterion
    from cellstress.core.io import json_ready
    from cellstress.human.actions import parse_actions
    from cellstress.sim.simulator import Simulator

    with spinner_while_compiling(), user_errors():
        check_criterion(criterion)
        c = with_criterion(load_cell(cell), criterion)
        sim = Simulator(c)
    with user_errors("--actions: "):
        indices = parse_actions(actions, sim.action_index)
    with spinner_while_compiling(), user_errors():
        trace = sim.run(indices)
    records = [r.model_dump() for r in trace.records()]
    hit = trace.unsafe_row
    hazard = None
    verdict = None
    if hit is not None:
        r = records[hit]
        hazard = {k: r[k] for k in ("t", "step", "robot_link", "body_part", "robot_point", "human_point",
                                    "d_HR", "v_R")}
        verdict = sim.verdict_at(trace, hit)
        if verdict is not None:  # a criterion that judges contacts: its account of this one
            hazard[sim.criterion.type] = verdict.as_dict()

    if as_json:
        doc = {"cell": c.name, "actions": [sim.action_names[i] for i in indices], "steps": records,
               "unsafe": hazard is not None, "hazard": hazard}
        say(json.dumps(json_ready(doc), indent=1, allow_nan=False))
        if hazard is not None:
            raise typer.Exit(1)
        return
    say(HEADER)
    for r in records:
        say(step_line(r))
    if hazard is None:
        say("SAFE")
    else:
        say(f"UNSAFE at t={num(hazard['t'])} s (step {hazard['step']}): "
                   f"{hazard['robot_link']} / {hazard['body_part']}")
        if verdict is not None:
            say(f"{sim.criterion.type}  {verdict.reason}")
        raise typer.Exit(1)
