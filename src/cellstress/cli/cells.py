"""``cellstress cells``: the built-in cells."""

from __future__ import annotations

from cellstress.cli.common import first_sentence, say
from cellstress.core.errors import CellstressError


def cells() -> None:
    """List the built-in cells with the first sentence of each description, where their files are, and the
    built-in robots."""
    import os

    import yaml

    from cellstress.cell.load import BUILTIN_CELLS, builtin_file, builtin_text
    from cellstress.robot.model import BUILTIN_ROBOTS

    width = max(len(n) for n in BUILTIN_CELLS)
    for name in BUILTIN_CELLS:
        try:
            data = yaml.safe_load(builtin_text(name))
        except CellstressError:
            say(f"{name:<{width}}  (missing)")
            continue
        except yaml.YAMLError:
            say(f"{name:<{width}}  (unreadable YAML: run 'cellstress check {name}')")
            continue
        description = data.get("description", "") if isinstance(data, dict) else ""
        say(f"{name:<{width}}  {first_sentence(str(description or '')) or '(no description)'}")
    say(f"files in {os.path.dirname(builtin_file(BUILTIN_CELLS[0]))} (NAME.yaml; docs/cell-format.md describes "
        "every field, 'cellstress new NAME' writes a starter cell)")
    say(f"robots: {', '.join(BUILTIN_ROBOTS)} (robot.urdf short names, from example-robot-data; "
        "'cellstress new NAME --robot panda' writes a starter cell with one)")
