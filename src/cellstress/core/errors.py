"""Errors a user can cause and fix. The CLI turns each into one message and exit code 2."""

from __future__ import annotations


class CellstressError(Exception):
    """A problem with the user's input: printed as one line, no traceback."""


class CellError(CellstressError):
    """A cell file is wrong. Names the file, the field path and the problem."""

    def __init__(self, source: str, field: str, problem: str):
        self.source = source
        self.field = field
        self.problem = problem
        where = f"{source}: {field}" if field else source
        super().__init__(f"{where}: {problem}")


class ActionError(CellstressError):
    """An action name or index that is not one of the 30 human actions."""


class PluginError(CellstressError):
    """An unknown plug-in name (searcher, device, criterion, simulator), or a plug-in that cannot be loaded."""
