"""Errors raised at the graph boundary.  Each names what was wrong."""

from __future__ import annotations


class GraphError(ValueError):
    """A refused edit or evaluation; `node` and `where` locate it."""

    def __init__(self, message: str, *, node: str | None = None, where: str | None = None,
                 index: int | None = None):
        super().__init__(message)
        self.node = node
        self.where = where
        self.index = index  # position of the refused item in a bulk edit (`GraphDocument.load_parts`)


class ParamError(GraphError):
    """A parameter value outside its schema."""

    def __init__(self, name: str, value, expected: str, *, node: str | None = None):
        self.param = name
        self.value = value
        self.expected = expected
        prefix = f"node {node!r}: " if node else ""
        super().__init__(
            f"{prefix}parameter {name!r} = {value!r} is invalid: expected {expected}",
            node=node,
            where=name,
        )

    def on_node(self, node: str) -> "ParamError":
        return ParamError(self.param, self.value, self.expected, node=node)


class NodeInputError(GraphError):
    """Raised by a node's evaluate when its inputs do not meet its requirements."""


class ProjectFileError(ValueError):
    """A project file that cannot be opened; names the path, where in it and the reason.

    path : the file as given.
    where : the location in the file -- a JSON path such as ``nodes[3].position[0]``,
        ``line 4, column 7`` or ``byte 120`` -- or "" when the whole file is at fault
        (missing, a directory, empty).
    reason : what is wrong, with the value found and what was expected.
    """

    def __init__(self, path, reason: str, *, where: str = ""):
        located = f"{where}: {reason}" if where else reason
        super().__init__(f"cannot open project {str(path)!r}: {located}")
        self.path = str(path)
        self.where = where
        self.reason = reason
