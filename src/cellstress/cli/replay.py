"""``cellstress replay``: re-simulate a result file's hazard and check it bit-exactly."""

from __future__ import annotations

import json
from typing import Annotated

import typer

from cellstress.cli.common import HEADER, fail, num, say, step_line, user_errors


def replay(
    result_file: Annotated[str, typer.Argument(help="A result.json written by 'cellstress search' (or its "
                                               "folder).")],
    hazard_index: Annotated[int | None, typer.Option("--hazard", help="Replay the distinct hazard with this "
                                                     "index (search --distinct) instead of the first.")] = None,
) -> None:
    """Re-simulate the hazard of a search result and check it bit-exactly against the recorded trace.

    Exit code 0 if the replay agrees with the file, 1 if it does not."""
    from cellstress.cell.load import load_cell, with_criterion
    from cellstress.cell.schema import DEFAULT_CRITERION
    from cellstress.core.io import json_ready
    from cellstress.searchers.result import SearchResult
    from cellstress.sim.simulator import Simulator

    with user_errors():
        res = SearchResult.load(result_file)
    h = res.hazard
    if hazard_index is not None:
        hs = res.distinct or ()
        if not 0 <= hazard_index < len(hs):
            raise fail(f"--hazard {hazard_index}: the result lists {len(hs)} distinct hazards"
                       + (f" (0..{len(hs) - 1})" if hs else ""))
        h = hs[hazard_index]
    if h is None:
        raise fail(f"{result_file}: the search found no hazard; there is nothing to replay")
    with user_errors():
        c = with_criterion(load_cell(res.cell.source), res.cell.criterion or DEFAULT_CRITERION)
        trace = Simulator(c).run(list(h.actions))
    records = [json_ready(r.model_dump()) for r in trace.records()]
    say(HEADER)
    for r in records:
        say(step_line(r))
    problems = []
    if c.sha256 != res.cell.sha256:
        problems.append(f"the cell differs from the one searched (sha256 {c.sha256[:12]} != "
                        f"{res.cell.sha256[:12]})")
    recorded = [json_ready(r.model_dump()) for r in h.trace]
    if len(records) != len(recorded):
        problems.append(f"the replay has {len(records)} rows, the file {len(recorded)}")
    for i, (a, b) in enumerate(zip(records, recorded, strict=False)):
        if json.dumps(a, sort_keys=True) != json.dumps(b, sort_keys=True):
            keys = sorted(k for k in set(a) | set(b) if json.dumps(a.get(k)) != json.dumps(b.get(k)))
            problems.append(f"row {i} differs in {', '.join(keys)}")
            break
    if not trace.unsafe:
        problems.append("the replayed episode does not reach an unsafe state")
    if problems:
        for p in problems:
            say(f"MISMATCH: {p}")
        raise typer.Exit(1)
    say(f"REPRODUCED bit-exactly: UNSAFE at t={num(h.time_s)} s (step {h.step}): "
               f"{h.robot_link} / {h.body_part}, v_R {h.v_R:.3f} m/s")
