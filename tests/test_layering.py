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


VALUE_HOMES = {
    "engine.geometry.values": ("Point", "EdgeChain", "LineElement", "SurfaceElement", "Skeleton", "Solid",
                               "VoxelModel", "Field", "MeshValue"),
    "engine.physics.values": ("Stiffness",),
    "engine.growth.values": ("TilingValue",),
    "engine.phasor.values": ("PhasorFieldsValue", "SliceEnergy"),
    "engine.topopt.values": ("DesignValue",),
    "engine.rd.values": ("RDFieldsValue", "RDStructuresValue", "ContourValue"),
    "engine.geometry.surfaces.values": ("SurfaceReport",),
}


def test_family_values_load_without_the_graph():
    """A family's value module is family code: importing it loads no graph or node module."""
    mods = ", ".join(VALUE_HOMES)
    code = (f"import sys, importlib; [importlib.import_module(m) for m in {list(VALUE_HOMES)!r}]; "
            "bad = [m for m in sys.modules if m.startswith(('engine.graph', 'engine.nodes'))]; "
            "print(bad); sys.exit(1 if bad else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, mods + ": " + r.stdout + r.stderr


def test_the_gpu_package_loads_no_family():
    """engine.gpu is the shared GL context under the families: importing it loads no phasor code."""
    code = ("import sys, engine.gpu; bad = [m for m in sys.modules if m.startswith('engine.phasor')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
