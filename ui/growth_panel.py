"""The "Virtual Growth" dock: a grown tiling as an image, its growth replayed,
hint regions painted on it, its realised block probabilities and (when a
Tiling Properties node follows it) the in-plane stiffness.

The panel shows the tiling of the node `engine.graph.query.pick_node` finds
for the selection among the nodes whose outputs hold one (the selected node,
else the nearest one above it, else the last one in the graph); the
stiffness of the Tiling Properties node it feeds. A 3D tiling is shown one
layer at a time (`LayerRow`, ``engine.growth.layers``).

The parts live beside it: pictures (`growth_images`), the replay
(`growth_replay`: the Grow node's `GrowthPlan` says what to replay), the
painting binding (`growth_regions`), the stiffness box (`growth_stiffness`).
This module lays them out and hands each the shown tiling.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtWidgets

from engine.graph import node_type
from engine.graph.query import downstream_of_type, pick_node
from engine.growth.values import TilingValue
from engine.physics.values import Stiffness
from engine.growth import UNASSIGNED, realised_probabilities
from engine.growth.layers import tiling_layer
from engine.nodes.growth_plan import GrowthPlan

from .growth_charts import PieChart
from .growth_images import layer_rgb, pixels_per_block, stiffness2d_of, tiling_of, tiling_rgb
from .growth_layers import LayerRow
from .growth_regions import RegionBinding
from .growth_replay import ReplayControls, ReplayController
from .growth_stiffness import StiffnessBox
from .region_canvas import RegionCanvas
from .region_tools import RegionTools

NO_TILING = "select a Grow node (or evaluate a graph with one)"


class GrowthPanel(QtWidgets.QWidget):
    """Dock content: tiling picture with painted regions, growth replay, 3D layers,
    block probabilities, 2D stiffness.

    Parameters
    ----------
    parent : QWidget, optional
    undo : engine.graph.UndoStack, optional
        Where paint strokes and region hints go; without it painting is off
        (see `set_undo`).
    """

    def __init__(self, parent=None, *, undo=None):
        super().__init__(parent)
        self.doc = None
        self.node_id: str | None = None
        self.value: TilingValue | None = None
        self.stiffness: Stiffness | None = None
        self.stiffness_id: str | None = None
        self.ppb = 20
        self.image_shape: tuple = ()  # (height, width) in pixels of the shown image
        self.shown_tiles: np.ndarray | None = None  # the whole grid shown (a layer of it in 3D)
        self.requested: np.ndarray | None = None

        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel(NO_TILING)
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)
        self.view = RegionCanvas()
        lay.addWidget(self.view, 3)
        self.layer_row = LayerRow()
        self.layer_row.changed.connect(self._on_layer)
        lay.addWidget(self.layer_row)

        self.replay_controls = ReplayControls()
        lay.addWidget(self.replay_controls)
        self.replay = ReplayController(self.replay_controls, self.assigned_count, self)
        self.replay.frame.connect(self._set_image)

        self.region_tools = RegionTools()
        lay.addWidget(self.region_tools)
        self.regions = RegionBinding(self.view, self.region_tools,
                                     lambda: (self.doc, self.node_id, self.value), self)

        lay.addWidget(QtWidgets.QLabel("<b>Realised block probabilities</b>"))
        self.pie = PieChart()
        lay.addWidget(self.pie, 1)
        self.stiffness_box = StiffnessBox()
        lay.addWidget(self.stiffness_box, 1)
        self.set_undo(undo)

    # -- parts the window and tests reach ----------------------------------------------------
    @property
    def undo(self):
        return self.regions.undo

    @property
    def play_button(self):
        return self.replay_controls.play_button

    @property
    def speed(self):
        return self.replay_controls.speed

    @property
    def anim_label(self):
        return self.replay_controls.label

    @property
    def timer(self):
        return self.replay.timer

    @property
    def stiffness_label(self):
        return self.stiffness_box.label

    @property
    def polar(self):
        return self.stiffness_box.polar

    @property
    def layer_slider(self):
        return self.layer_row.slider

    @property
    def layer_axis(self):
        return self.layer_row.axis_box

    @property
    def axis(self) -> str:
        return self.layer_row.axis

    @property
    def layer(self) -> int:
        return self.layer_row.layer

    def set_layer(self, axis: str, index: int) -> None:
        """Show layer ``index`` along ``axis`` ("z", "y" or "x") of a 3D tiling."""
        self.layer_row.set_layer(axis, index)

    # -- document and undo --------------------------------------------------------------------
    def set_undo(self, undo) -> None:
        """Where paint strokes go (an UndoStack over the shown document); None turns painting off."""
        self.regions.set_undo(undo)

    def detach(self) -> None:
        """Stop following the document and stop the replay (the window is closing)."""
        self.replay.shutdown()
        self.regions.watch(None)

    def paint_block_reason(self) -> str | None:
        """Why painting is off now, or None when it is on."""
        return self.regions.block_reason()

    def clear_regions(self) -> None:
        """Remove every painted region: one undo step (nothing if nothing is painted)."""
        self.regions.clear_regions()

    # -- context ------------------------------------------------------------------------------
    def set_context(self, doc, outputs: dict, selected: str | None) -> None:
        """Pick the tiling to show from the latest evaluation outputs and the selection."""
        self.doc = doc
        self.regions.watch(doc if doc is not None else getattr(self.undo, "doc", None))
        outputs = {k: v for k, v in (outputs or {}).items() if doc is None or k in doc.nodes}
        node_id = self._pick_tiling(doc, outputs, selected)
        value = tiling_of(outputs[node_id]) if node_id else None
        stiffness_id = downstream_of_type(doc, node_id, "TilingProperties")
        stiffness = stiffness2d_of(outputs.get(stiffness_id)) if stiffness_id else None
        if stiffness is None:
            stiffness_id = None
        if value is self.value and node_id == self.node_id and stiffness is self.stiffness:
            return  # nothing changed: keep a running replay going
        self.node_id, self.value = node_id, value
        self.stiffness_id, self.stiffness = stiffness_id, stiffness
        self._show_tiling()
        self.stiffness_box.show_stiffness(stiffness_id, stiffness)
        self.regions.refresh()

    def _pick_tiling(self, doc, outputs, selected):
        def holds_tiling(nid):
            return nid in outputs and tiling_of(outputs[nid]) is not None
        if doc is None:   # outputs without a document: the selected one, else the last
            return selected if holds_tiling(selected) else next(
                (n for n in reversed(list(outputs)) if holds_tiling(n)), None)
        return pick_node(doc, selected, holds_tiling, previous=self.node_id)

    def plan_of(self, value: TilingValue, *, seed: int | None = None) -> GrowthPlan | None:
        """The Grow node's plan for ``value``: its current parameters and the seed
        the tiling was grown with (or ``seed``); None when they are not known."""
        node = self.regions.grow_node()
        seed = getattr(value.tiling, "seed", None) if seed is None else seed
        if node is None or seed is None:
            return None
        try:
            params = node_type("Grow").validate_params(node.params)
            return GrowthPlan.from_params(params, value.tileset, seed)
        except Exception:   # parameters that no longer fit the shown tiling
            return None

    # -- tiling ---------------------------------------------------------------------------------
    def _show_tiling(self) -> None:
        tv = self.value
        self.replay.set_source(tv, self.plan_of if tv is not None else None)
        if tv is None:
            self.caption.setText(NO_TILING)
            self.layer_row.hide()
            self._set_image(None)
            self.pie.set_data([], [])
            return
        t = tv.tiling
        dims = " × ".join(str(s) for s in t.shape[::-1])
        self.caption.setText(f"<b>{self.node_id}</b>: {dims} blocks ({tv.tileset.name}), "
                             f"periodic: {'yes' if t.periodic else 'no'}, "
                             f"defects: {t.n_defects}, seed: {t.seed}")
        self.ppb = pixels_per_block(t.shape)
        self.layer_row.setVisible(tv.ndim == 3)
        if tv.ndim == 3:
            self.layer_row.fit(t.shape)
        self._set_image(np.asarray(t.tiles))
        self.requested = self._requested_blocks()
        self.pie.set_data(tv.tileset.block_names, realised_probabilities(t, tv.tileset), self.requested)

    def _requested_blocks(self) -> np.ndarray | None:
        """Block probabilities the node asks for (the plan's, from its current parameters)."""
        plan = self.plan_of(self.value, seed=0)    # the seed plays no part in the request
        return None if plan is None else plan.requested_blocks()

    def _on_layer(self) -> None:
        if self.value is not None and self.value.ndim == 3:
            self._set_image(self.shown_tiles)

    def _set_image(self, tiles: np.ndarray | None) -> None:
        """Show the whole grid ``tiles`` (one layer of it in 3D); None clears."""
        if tiles is None:
            self.shown_tiles, self.image_shape = None, ()
            self.view.set_grid(None, None)
            return
        tv = self.value
        self.shown_tiles = np.array(tiles)
        if self.shown_tiles.ndim == 2:
            rgb = tiling_rgb(tiles, tv.tileset, tv.tiling.tileset_name, tv.tiling.periodic, self.ppb)
            cells = self.shown_tiles
        else:
            rgb = layer_rgb(self.shown_tiles, tv.tileset, self.axis, self.layer, self.ppb)
            cells = tiling_layer(self.shown_tiles, self.axis, self.layer)
        self.image_shape = rgb.shape[:2]
        self.view.set_grid(rgb, cells)

    # -- replay -----------------------------------------------------------------------------------
    @property
    def n_steps(self) -> int:
        return self.replay.n_steps

    @property
    def anim_pos(self) -> int:
        return self.replay.pos

    @property
    def replay_note(self) -> str:
        return self.replay.note

    @property
    def replay_error(self) -> str:
        return self.replay.error

    @property
    def playing(self) -> bool:
        return self.replay.playing

    def prepare_replay(self) -> bool:
        """True when the replay of the shown tiling is ready (else it is being grown)."""
        return self.replay.prepare()

    def assigned_count(self) -> int:
        """Cells shown as decided (tile or defect) in the whole shown grid."""
        if self.shown_tiles is None:
            return 0
        return int(np.count_nonzero(self.shown_tiles != UNASSIGNED))

    def restart(self) -> None:
        self.replay.restart()

    def step(self, n: int = 1) -> int:
        """Reveal the next ``n`` growth events; returns the number of assigned cells shown."""
        self.replay.step(n)
        return self.assigned_count()

    def play(self) -> None:
        self.replay.play()

    def pause(self) -> None:
        self.replay.pause()

    def _tick(self) -> None:
        self.replay.tick()
