"""Fixtures for the window tests: a real MainWindow under Xvfb, no dialogs."""

from __future__ import annotations

import pytest

from engine.graph import AddNode, Connect


class FakePrompter:
    """Answers the window's questions without showing dialogs and records what was shown."""

    def __init__(self):
        self.unsaved_answer = "discard"
        self.recover_answer = False
        self.open_answer = None
        self.save_answer = None
        self.errors: list[tuple[str, str]] = []
        self.unsaved_asked = 0
        self.recover_asked: list = []

    def ask_unsaved(self, name):
        self.unsaved_asked += 1
        return self.unsaved_answer

    def error(self, title, text):
        self.errors.append((title, text))

    def open_path(self, caption, directory="", filters=""):
        return self.open_answer

    def save_path(self, caption, directory="", filters=""):
        return self.save_answer

    def ask_recover(self, items):
        self.recover_asked.append(list(items))
        return self.recover_answer


@pytest.fixture
def prompter():
    return FakePrompter()


@pytest.fixture
def make_window(qtbot, tmp_path, prompter):
    """Factory for MainWindows; every window is closed (plotter released) at teardown."""
    from app.gui import create_main_window

    windows = []

    def make(project_path=None, **kwargs):
        kwargs.setdefault("autosave_dir", tmp_path / "autosave")
        kwargs.setdefault("prompter", prompter)
        w = create_main_window(project_path, **kwargs)
        w.resize(1400, 850)
        w.show()
        qtbot.waitExposed(w)
        windows.append(w)
        return w

    yield make
    for w in windows:
        prompter.unsaved_answer = "discard"
        w.close()
        assert w.viewport._closed, "the VTK render window must be released"
        assert not w.worker.is_busy
        w.deleteLater()
    qtbot.wait(10)


@pytest.fixture
def window(make_window):
    return make_window()


def build_strut_graph(undo, resolution=32, thickness=0.15):
    """Vertex x2 -> EdgeChain -> Line -> Object -> Voxel, pushed as commands; returns the ids."""
    ids = {}
    ids["v1"] = undo.push(AddNode("Vertex", {"position": [0.2, 0.5, 0.5]}, (0, 0))).node_id
    ids["v2"] = undo.push(AddNode("Vertex", {"position": [0.8, 0.5, 0.5]}, (0, 160))).node_id
    ids["e"] = undo.push(AddNode("EdgeChain", {}, (240, 80))).node_id
    undo.push(Connect(ids["v1"], "point", ids["e"], "vertices"))
    undo.push(Connect(ids["v2"], "point", ids["e"], "vertices"))
    ids["l"] = undo.push(AddNode("Line", {"thickness": [[0.0, thickness], [1.0, thickness]]}, (480, 80))).node_id
    undo.push(Connect(ids["e"], "chain", ids["l"], "chains"))
    ids["obj"] = undo.push(AddNode("Object", {"resolution": resolution}, (720, 80))).node_id
    undo.push(Connect(ids["l"], "skeleton", ids["obj"], "skeleton"))
    ids["vox"] = undo.push(AddNode("Voxel", {}, (960, 80))).node_id
    undo.push(Connect(ids["obj"], "solid", ids["vox"], "solid"))
    return ids


def wait_for_evaluation(qtbot, window, after: int, timeout: int = 60000):
    """Wait until an evaluation finished after `after` (an eval_count) and nothing is pending."""
    qtbot.waitUntil(lambda: window.eval_count > after and window.evaluation_idle, timeout=timeout)
    return window.last_report


@pytest.fixture
def strut_graph():
    return build_strut_graph


@pytest.fixture
def wait_eval(qtbot):
    def wait(window, after, timeout=60000):
        return wait_for_evaluation(qtbot, window, after, timeout)
    return wait


def build_slow_graph(undo, resolution=256):
    """The strut graph mirrored four times and rotated (32 thick struts) at `resolution`:
    seconds of work in the Object node, so there is time to cancel."""
    from engine.graph import Disconnect
    ids = build_strut_graph(undo, resolution=resolution, thickness=0.5)
    undo.push(Disconnect(ids["l"], "skeleton", ids["obj"], "skeleton"))
    prev = ids["l"]
    for k, d in enumerate(([1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0])):
        m = undo.push(AddNode("Mirror", {"direction": d}, (480 + 60 * k, 240 + 60 * k))).node_id
        undo.push(Connect(prev, "skeleton", m, "skeleton"))
        prev = m
    t = undo.push(AddNode("Transform", {"rotation_angle": 45.0, "rotation_axis": [1, 1, 0]}, (700, 300))).node_id
    undo.push(Connect(prev, "skeleton", t, "skeleton"))
    undo.push(Connect(t, "skeleton", ids["obj"], "skeleton"))
    return ids


@pytest.fixture
def slow_graph():
    return build_slow_graph
