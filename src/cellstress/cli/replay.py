"""``cellstress replay``: re-simulate a result file's hazard and check every claim of the file."""

from __future__ import annotations

from typing import Annotated

import typer

from cellstress.cli.common import HEADER, num, say, spinner_while_compiling, step_line, user_errors


def replay(
    result_file: Annotated[str, typer.Argument(help="A result.json written by 'cellstress search' (or its "
                                               "folder).")],
    hazard_index: Annotated[int | None, typer.Option("--hazard", help="Replay the distinct hazard with this "
                                                     "index (search --distinct) instead of the first.")] = None,
    no_search: Annotated[bool, typer.Option("--no-search", help="Check only the hazard (its trace and "
                                            "summary), not the search that found it (its seed, episode "
                                            "numbers, kept episodes and risks), which costs a search.")] = False,
) -> None:
    """Re-simulate the hazard of a search result, check it bit-exactly against the file, and run the search
    again to check every other claim of the file (seed, episodes, risks).

    Exit code 0 if everything agrees, 1 if anything does not (each MISMATCH line names the field), 2 for a
    file that is not a result file."""
    from cellstress.analysis.replay import check_result
    from cellstress.core.io import json_ready
    from cellstress.searchers.result import SearchResult

    with spinner_while_compiling(), user_errors():
        res = SearchResult.load(result_file)
        check = check_result(res, hazard_index, search_again=not no_search)
    say(HEADER)
    for r in check.trace.records():
        say(step_line(json_ready(r.model_dump())))
    if check.problems:
        for p in check.problems:
            say(f"MISMATCH: {p}")
        raise typer.Exit(1)
    h = check.hazard
    scope = ("the hazard only; the search was not run again (--no-search)" if not check.searched_again
             else "the search run again gives the same file")
    say(f"REPRODUCED bit-exactly: UNSAFE at t={num(h.time_s)} s (step {h.step}): "
        f"{h.robot_link} / {h.body_part}, v_R {h.v_R:.3f} m/s ({scope})")
