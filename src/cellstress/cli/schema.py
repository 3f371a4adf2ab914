"""``cellstress schema``: the cell file format as a JSON Schema (for editors) or as the field reference."""

from __future__ import annotations

import json
from typing import Annotated

import typer

from cellstress.cli.common import say


def schema(
    as_markdown: Annotated[bool, typer.Option("--markdown", help="Print the field reference (docs/cell-format.md) "
                                              "instead of the JSON Schema.")] = False,
) -> None:
    """Print the JSON Schema of cell files (e.g. 'cellstress schema > cell.schema.json', for a YAML editor's
    validation and completion), or with --markdown the reference of every field."""
    from cellstress.cell.reference import json_schema, markdown

    say(markdown() if as_markdown else json.dumps(json_schema(), indent=1, sort_keys=True), nl=not as_markdown)
