"""Graph document, undoable commands, incremental evaluator, project files."""

from .commands import (AddNode, Command, Connect, Disconnect, Macro, MoveNode, RemoveNode, SetLabel,
                       SetParam, SetSeed, UndoStack)
from .document import Edge, GraphDocument, GraphSnapshot, NodeInstance
from .annotation_commands import (AddFrame, EditFrame, ExposeParam, MakeSubgraph, RemoveFrame, RenameSubgraph,
                                  SetSubgraphCollapsed, SetSubgraphParam, UnexposeParam, Ungroup)
from .annotations import ExposedParam, Frame, Subgraph
from .errors import GraphError, NodeInputError, ParamError, ProjectFileError
from .evaluator import EvalReport, Evaluator, NodeResult
from .node import (Cancelled, CancelToken, EvalContext, NodeType, all_node_types,
                   node_type, register)
from .project import document_from_dict, document_to_dict, load_project, save_project, write_atomic
from .clipboard import PasteFragment, fragment_from_text, fragment_of, fragment_to_text
from .layout import layered_positions
from .schema import Param, Port

__all__ = [
    "AddNode", "Command", "Connect", "Disconnect", "Macro", "MoveNode", "RemoveNode", "SetLabel",
    "SetParam", "SetSeed", "UndoStack", "Edge", "GraphDocument", "GraphSnapshot", "NodeInstance",
    "GraphError", "NodeInputError", "ParamError", "ProjectFileError", "EvalReport", "Evaluator",
    "NodeResult", "Cancelled", "CancelToken", "EvalContext", "NodeType",
    "all_node_types", "node_type", "register", "document_from_dict", "document_to_dict",
    "load_project", "save_project", "write_atomic", "Param", "Port",
    "PasteFragment", "fragment_of", "fragment_from_text", "fragment_to_text", "layered_positions",
    "AddFrame", "EditFrame", "ExposeParam", "MakeSubgraph", "RemoveFrame", "RenameSubgraph",
    "SetSubgraphCollapsed", "SetSubgraphParam", "UnexposeParam", "Ungroup", "ExposedParam", "Frame", "Subgraph",
]
