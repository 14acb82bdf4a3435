"""Painting tools of the Virtual Growth dock: label, brush, clear, legend, hints per label.

The tools only say what the user asked for (signals); the panel turns each
request into one `SetParam` on the undo stack. The hints of each painted
label are edited as text ("T=3,+=1") and checked against the node's tile
set before anything is sent; a refused text stays in its field, with a
message naming the label and the problem. Texts typed but not applied are
kept across refreshes (strokes, undo) until they match the document.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.batch.hints_text import parse_hints
from engine.growth.regions import N_LABELS, format_region_hints, label_name, parse_region_hints
from engine.nodes.growth_tools import REGION_BRUSH_RADIUS, region_brush_check

from .region_canvas import label_rgb
from .tool_number import ToolNumber

N_BRUSH_LABELS = 10   # labels offered by the picker (0 erases); maps may hold up to N_LABELS
ERROR_STYLE = "color: #c02020;"
FIELD_ERROR_STYLE = "QLineEdit { border: 1px solid #d03030; }"


def swatch_icon(label: int, size: int = 12) -> QtGui.QIcon:
    pix = QtGui.QPixmap(size, size)
    pix.fill(QtCore.Qt.GlobalColor.transparent)
    p = QtGui.QPainter(pix)
    p.setPen(QtGui.QPen(QtGui.QColor(90, 90, 90), 1))
    if label:
        p.setBrush(QtGui.QColor(*label_rgb(label)))
    p.drawRect(0, 0, size - 1, size - 1)
    if not label:   # label 0: the node's own hints, drawn as a crossed box
        p.drawLine(0, 0, size - 1, size - 1)
    p.end()
    return QtGui.QIcon(pix)


class RegionTools(QtWidgets.QGroupBox):
    """Label picker, brush radius, overlay switch, clear, legend and region-hints editor."""

    labelChosen = QtCore.Signal(int)
    radiusChanged = QtCore.Signal(float)
    overlayToggled = QtCore.Signal(bool)
    clearRequested = QtCore.Signal()
    hintsApplied = QtCore.Signal(str)   # a validated region_hints text, different from the document's

    def __init__(self, parent=None):
        super().__init__("Painted hint regions", parent)
        self.tileset = None
        self.doc_text = ""
        self.doc_texts: dict[int, str] = {}
        self.drafts: dict[int, str] = {}
        self.counts = np.zeros(N_LABELS, dtype=np.int64)
        self.fields: dict[int, QtWidgets.QLineEdit] = {}
        self._count_labels: dict[int, QtWidgets.QLabel] = {}

        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        lay.addWidget(self.status)

        picker = QtWidgets.QHBoxLayout()
        picker.setSpacing(1)
        self.label_group = QtWidgets.QButtonGroup(self)
        self.label_group.setExclusive(True)
        self.label_buttons: list[QtWidgets.QToolButton] = []
        for k in range(N_BRUSH_LABELS):
            b = QtWidgets.QToolButton()
            b.setCheckable(True)
            b.setIcon(swatch_icon(k))
            b.setText("erase" if k == 0 else label_name(k))
            b.setToolButtonStyle(QtCore.Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
            b.setToolTip("label 0: erase (cells take the node's own hints)" if k == 0
                         else f"paint label {label_name(k)}")
            self.label_group.addButton(b, k)
            self.label_buttons.append(b)
            picker.addWidget(b)
        picker.addStretch(1)
        self.label_buttons[1].setChecked(True)
        self.label_group.idClicked.connect(self.labelChosen)
        lay.addLayout(picker)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Brush radius"))
        # paint_disc's rule (engine.nodes.growth_tools): a typed radius is never clamped
        self.radius = ToolNumber(REGION_BRUSH_RADIUS, check=region_brush_check)
        self.radius.valueChanged.connect(lambda r: self.radiusChanged.emit(float(r)))
        row.addWidget(self.radius, 0, QtCore.Qt.AlignmentFlag.AlignTop)
        self.show_overlay = QtWidgets.QCheckBox("Show")
        self.show_overlay.setChecked(True)
        self.show_overlay.toggled.connect(self.overlayToggled)
        row.addWidget(self.show_overlay)
        row.addStretch(1)
        self.clear_button = QtWidgets.QPushButton("Clear all")
        self.clear_button.setToolTip("remove every painted region (one undo step)")
        self.clear_button.clicked.connect(self.clearRequested)
        row.addWidget(self.clear_button)
        lay.addLayout(row)

        self.legend = QtWidgets.QWidget()
        self.grid = QtWidgets.QGridLayout(self.legend)
        self.grid.setContentsMargins(0, 0, 0, 0)
        self.grid.setColumnStretch(2, 1)
        lay.addWidget(self.legend)

        bottom = QtWidgets.QHBoxLayout()
        self.message = QtWidgets.QLabel("")
        self.message.setWordWrap(True)
        bottom.addWidget(self.message, 1)
        self.apply_button = QtWidgets.QPushButton("Apply hints")
        self.apply_button.setToolTip("set the hints of every painted label (one undo step)")
        self.apply_button.clicked.connect(self.apply)
        bottom.addWidget(self.apply_button, 0, QtCore.Qt.AlignmentFlag.AlignTop)
        lay.addLayout(bottom)
        self._rebuild([])

    # -- state from the document --------------------------------------------------------------
    @property
    def paint_label(self) -> int:
        return max(0, self.label_group.checkedId())

    def set_available(self, reason: str | None) -> None:
        """Enable the tools (reason None) or disable them, saying why."""
        self.setEnabled(reason is None)
        self.setToolTip(reason or "")
        self.status.setText(reason or "drag on the tiling to paint (right button erases); "
                                      "each stroke is one undo step")

    def set_state(self, labels: np.ndarray | None, region_hints: str, base_hints: str, tileset) -> None:
        """Show the document's label map and region hints (keeps unapplied texts)."""
        self.tileset = tileset
        lab = np.zeros(0, np.int64) if labels is None else np.asarray(labels).ravel()
        self.counts = np.bincount(lab, minlength=N_LABELS)[:N_LABELS]
        self.doc_text = region_hints or ""
        try:
            self.doc_texts = parse_region_hints(self.doc_text, str.strip)
            note = ""
        except ValueError as exc:
            self.doc_texts = {}
            note = f"the region_hints text cannot be read ({exc}); applying replaces it"
        self.drafts = {k: v for k, v in self.drafts.items()
                       if v.strip() != self.doc_texts.get(k, "")}
        used = sorted({int(k) for k in np.flatnonzero(self.counts) if k}
                      | {k for k in self.doc_texts if k} | set(self.drafts))
        if used != sorted(self.fields):
            self._rebuild(used)
        for k, field in self.fields.items():
            if k not in self.drafts and field.text() != self.doc_texts.get(k, ""):
                field.setText(self.doc_texts.get(k, ""))
        for k, lbl in self._count_labels.items():
            lbl.setText(self._count_text(k))
        self.base_label.setText(f"node's hints: {base_hints.strip() or 'tile-set weights'}")
        if note:
            self.show_message(note, error=True)

    def _count_text(self, k: int) -> str:
        n = int(self.counts[k]) if k < len(self.counts) else 0
        return f"{label_name(k)}  ({n} cell{'' if n == 1 else 's'})"

    def _rebuild(self, used: list[int]) -> None:
        while self.grid.count():
            w = self.grid.takeAt(0).widget()
            if w is not None:
                w.hide()   # deleteLater waits for the event loop; hide the old row now
                w.deleteLater()
        self.fields, self._count_labels = {}, {}
        for r, k in enumerate([0] + list(used)):
            icon = QtWidgets.QLabel()
            icon.setPixmap(swatch_icon(k).pixmap(12, 12))
            self.grid.addWidget(icon, r, 0)
            count = QtWidgets.QLabel(self._count_text(k))
            self._count_labels[k] = count
            self.grid.addWidget(count, r, 1)
            if k == 0:
                self.base_label = QtWidgets.QLabel("")
                self.grid.addWidget(self.base_label, r, 2)
                continue
            field = QtWidgets.QLineEdit(self.drafts.get(k, self.doc_texts.get(k, "")))
            field.setPlaceholderText("hints, e.g. T=3,+=1 (empty: the node's hints)")
            field.setToolTip(f"frequency hints of the cells painted with label {label_name(k)}")
            field.textEdited.connect(lambda text, k=k: self._on_edited(k, text))
            field.returnPressed.connect(self.apply)
            self.fields[k] = field
            self.grid.addWidget(field, r, 2)

    def _on_edited(self, label: int, text: str) -> None:
        self.drafts[label] = text
        self.fields[label].setStyleSheet("")

    # -- applying -----------------------------------------------------------------------------
    def show_message(self, text: str, *, error: bool = False) -> None:
        self.message.setStyleSheet(ERROR_STYLE if error else "")
        self.message.setText(text)

    def composed_hints(self) -> str | None:
        """The region_hints text the fields say, or None (with a message) if one is refused."""
        if self.tileset is None:
            self.show_message("no tile set is known for this tiling: evaluate the graph first",
                              error=True)
            return None
        texts = dict(self.doc_texts)   # entries without a row (label 0) are kept
        for k, field in self.fields.items():
            text = field.text().strip()
            try:
                if "|" in text:
                    raise ValueError("'|' separates labels and cannot appear in hints")
                if text:
                    parse_hints(text, self.tileset)
            except ValueError as exc:
                field.setStyleSheet(FIELD_ERROR_STYLE)
                field.setFocus()
                self.show_message(f"label {label_name(k)}: {exc}", error=True)
                return None
            field.setStyleSheet("")
            texts[k] = text
        return format_region_hints(texts)

    def apply(self) -> None:
        text = self.composed_hints()
        if text is None:
            return
        if text == self.doc_text.strip():
            self.drafts.clear()
            self.show_message("hints unchanged")
            return
        self.show_message("")
        self.hintsApplied.emit(text)
