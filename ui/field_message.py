"""Refusals shown at the field: a red frame on its inputs and a message under it.

Also the words of a parameter's tooltip and of a refusal, both from the
parameter's schema (`Param.allowed()`, unit, default), so the editor says
exactly what the engine accepts.
"""

from __future__ import annotations

from typing import Any, Iterable

from PySide6 import QtCore, QtWidgets

from engine.graph import GraphError, Param, ParamError

REFUSED_COLOUR = "#e04040"
_FRAME = f"border: 1px solid {REFUSED_COLOUR}; border-radius: 2px;"
_NUMBER_KINDS = ("float", "int", "vec3", "int_list")


def _unit(param: Param) -> str:
    return f" {param.unit}" if param.unit else ""


def param_tooltip(param: Param) -> str:
    """Doc, what is allowed (range and unit) and the default of `param`."""
    lines = [param.doc] if param.doc else []
    lines.append(f"allowed: {param.allowed()}{_unit(param) if param.kind in _NUMBER_KINDS else ''}")
    if param.unit:
        lines.append(f"unit: {param.unit}")
    if param.kind not in ("json", "samples"):
        lines.append(f"default: {shown(param.default)}")
    return "\n".join(lines)


def shown(value: Any) -> str:
    """A value as the message quotes it: numbers plainly, text quoted, long data cut."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        text = "[" + ", ".join(shown(v) for v in value) + "]"
    else:
        text = repr(value) if isinstance(value, str) else str(value)
    return text if len(text) <= 80 else text[:77] + "..."


def refusal_text(param: Param, exc: GraphError, stored: Any) -> str:
    """``resolution = 1000 refused: expected an integer in [8, 512] voxels; kept 96``."""
    if not isinstance(exc, ParamError):
        return f"{param.name}: {exc}; kept {shown(stored)}"
    expected = f"{param.allowed()}{_unit(param)}" if param.kind in _NUMBER_KINDS else exc.expected
    return f"{param.name} = {shown(exc.value)} refused: expected {expected}; kept {shown(stored)}"


class FieldMessage(QtWidgets.QLabel):
    """The message under one field: hidden until `refuse`, which also frames the
    field's inputs red; `clear` takes both away."""

    def __init__(self, inputs: Iterable[QtWidgets.QWidget], parent=None):
        super().__init__(parent)
        self.inputs = list(inputs)
        self.setWordWrap(True)
        self.setStyleSheet(f"color: {REFUSED_COLOUR};")
        self.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        self.hide()

    @property
    def refused(self) -> bool:
        return bool(self.text()) and not self.isHidden()

    def refuse(self, text: str) -> None:
        self.setText(text)
        self.show()
        for w in self.inputs:
            _mark(w, True)
            w.setToolTip(_with_refusal(w.toolTip(), text))

    def clear(self) -> None:
        if self.isHidden() and not self.text():
            return
        self.setText("")
        self.hide()
        for w in self.inputs:
            _mark(w, False)
            w.setToolTip(_with_refusal(w.toolTip(), None))


_MARK = "\n\nrefused: "


def _mark(widget: QtWidgets.QWidget, refused: bool) -> None:
    """Frame `widget` red (or not): spin boxes paint the frame themselves (`NumberBox`)."""
    widget.setProperty("refused", refused)
    if isinstance(widget, QtWidgets.QAbstractSpinBox):
        widget.update()
    else:
        widget.setStyleSheet(_FRAME if refused else "")


def _with_refusal(tip: str, text: str | None) -> str:
    base = tip.split(_MARK)[0]
    return base if text is None else f"{base}{_MARK}{text}"
