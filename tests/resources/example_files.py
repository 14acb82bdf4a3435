"""Shared by the example tests: load a generator script, evaluate an example
with its Object nodes at a test resolution."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from engine.graph import Evaluator, SetParam, UndoStack, load_project

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES_DIR = ROOT / "resources" / "examples"


def load_tool(stem: str):
    """The module tools/<stem>.py, loaded from its file."""
    spec = importlib.util.spec_from_file_location(stem, ROOT / "tools" / f"{stem}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def evaluate_at(path: Path, resolution: int):
    """(document, report) of the example at ``path`` with every Object node at ``resolution``."""
    doc = load_project(path)
    stack = UndoStack(doc)
    for node_id, node in doc.nodes.items():
        if node.type_name == "Object":
            stack.push(SetParam(node_id, "resolution", resolution))
    return doc, Evaluator().evaluate(doc)
