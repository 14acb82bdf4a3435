"""The engine must stay importable without Qt (ARCHITECTURE.md)."""

import subprocess
import sys


def test_engine_import_leaves_qt_out():
    code = ("import sys, engine, engine.graph, engine.nodes, engine.geometry; "
            "from engine.graph import all_node_types; all_node_types(); "
            "bad = [m for m in sys.modules if m.split('.')[0] in "
            "('PySide6', 'PyQt5', 'PyQt6', 'qtpy', 'pyvistaqt', 'NodeGraphQt', 'ui', 'app')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
