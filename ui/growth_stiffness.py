"""The in-plane stiffness box of the Virtual Growth dock (a Tiling Properties result)."""

from __future__ import annotations

from PySide6 import QtWidgets

from .growth_charts import PolarPlot


class StiffnessBox(QtWidgets.QGroupBox):
    """E_avg, nu_avg, density and the polar plot of E(theta) of a 2D Stiffness."""

    def __init__(self, parent=None):
        super().__init__("In-plane stiffness", parent)
        sl = QtWidgets.QHBoxLayout(self)
        self.label = QtWidgets.QLabel()
        self.label.setWordWrap(True)
        self.polar = PolarPlot()
        sl.addWidget(self.label, 1)
        sl.addWidget(self.polar)
        self.hide()

    def show_stiffness(self, node_id: str | None, st) -> None:
        """Show ``st`` (a 2D Stiffness) of node ``node_id``; None hides the box."""
        if st is None:
            self.hide()
            return
        c = st.constants
        e_avg, nu_avg = c.get("E_avg", float("nan")), c.get("nu_avg", float("nan"))
        self.label.setText(f"<b>{node_id}</b><br>E_avg / E_s = {e_avg / st.E:.4g}"
                           f"<br>nu_avg = {nu_avg:.4g}<br>density = {st.density:.3f}")
        try:
            from engine.physics.material_sphere import material_polar
            theta, e = material_polar(st.C, n=180)
            self.polar.set_curve(theta, e)
        except Exception:  # a singular C has no polar curve
            self.polar.set_curve([], [])
        self.show()
