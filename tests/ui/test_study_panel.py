"""The Studies dock: real studies run out of process, cancelled, resumed and plotted."""

from __future__ import annotations

import numpy as np
import psutil
import pytest

from engine.batch import read_study, sample_seed, sweep_hints
from ui.study_panel import StudyPanel

TWO_GROUPS = "T=1,L=1,+=1,-=1\nT=4,L=1,+=1,-=1"
BLOCKS = ("T", "L", "-", "+")


@pytest.fixture
def panel(qtbot):
    """A StudyPanel whose study processes (and their Dask workers) are all gone at teardown."""
    p = StudyPanel()
    p.resize(700, 900)
    qtbot.addWidget(p)
    p.show()
    qtbot.waitExposed(p)
    p.confirm_replace = lambda path: True
    seen: dict = {}

    def watch(_value=None):
        pid = p.process_id()
        if not pid:
            return
        try:
            proc = psutil.Process(pid)
            seen[pid] = proc
            for child in proc.children(recursive=True):
                seen[child.pid] = child
        except psutil.NoSuchProcess:
            pass

    p.progress.valueChanged.connect(watch)
    p.watch_processes = watch
    yield p
    p.shutdown()
    assert not p.is_running
    _, alive = psutil.wait_procs(list(seen.values()), timeout=15)
    for proc in alive:
        proc.kill()
    assert not alive, f"study processes outlived the test: {alive}"


def _fill(panel, out, *, groups=TWO_GROUPS, n=3, size="6x6", resolution=10, workers=1):
    panel.tileset_box.setCurrentText("TL+-")
    panel.size_edit.setText(size)
    panel.samples_spin.setValue(n)
    panel.resolution_spin.setValue(resolution)
    panel.workers_spin.setValue(workers)
    panel.groups_radio.setChecked(True)
    panel.groups_edit.setPlainText(groups)
    panel.out_edit.setText(str(out))


def _wait_finished(qtbot, panel, timeout=90000):
    qtbot.waitUntil(lambda: not panel.is_running, timeout=timeout)
    return panel.last_exit_code


def test_tiny_study_runs_out_of_process_and_plots(qtbot, panel, tmp_path):
    out = tmp_path / "study.csv"
    _fill(panel, out)
    values = []
    panel.progress.valueChanged.connect(values.append)
    assert panel.run()
    assert panel.is_running and panel.process_id() not in (None, 0)
    assert not panel.run_button.isEnabled() and panel.cancel_button.isEnabled()
    code = _wait_finished(qtbot, panel)
    assert code == 0, panel.error_log.toPlainText()
    assert panel.progress.maximum() == 6 and panel.progress.value() == 6
    assert values == sorted(values) and values[-1] == 6
    assert panel.run_button.isEnabled() and not panel.cancel_button.isEnabled()
    assert "Done: 6 of 6 samples" in panel.status.text()

    rows = read_study(out)
    assert len(rows) == 6 and sorted({r["set"] for r in rows}) == [0, 1]
    assert [r["seed"] for r in rows] == [sample_seed(0, j, i) for j in (0, 1) for i in range(3)]

    # scatter: one collection per group, one point per status-ok row, at (E_avg/E_s, nu_avg)
    points = panel.plots.scatter_points()
    assert len(points) == 2
    for j, (label, pts) in enumerate(points):
        ok = [r for r in rows if r["set"] == j and r["status"] == "ok"]
        assert label.startswith(f"{j + 1}: ")
        assert pts.shape == (len(ok), 2)
        np.testing.assert_allclose(pts, [[r["E_avg/E_s"], r["nu_avg"]] for r in ok], rtol=1e-12)
    means = dict(panel.plots.scatter_means())
    for j, (label, pts) in enumerate(points):
        np.testing.assert_allclose(means[label][0], pts.mean(axis=0), rtol=1e-12)

    # pies: requested hints next to the mean realised probabilities, each summing to 1
    pies = panel.plots.pie_fractions()
    assert len(pies) == 2
    requested = {0: [0.25, 0.25, 0.25, 0.25], 1: [4 / 7, 1 / 7, 1 / 7, 1 / 7]}   # T, L, -, +
    for j, (_label, req, real) in enumerate(pies):
        np.testing.assert_allclose(req, requested[j], rtol=1e-9)
        grown = [r for r in rows if r["set"] == j and r["status"] in ("ok", "singular")]
        p = np.array([[r[f"p_{b}"] for b in BLOCKS] for r in grown]).mean(axis=0)
        assert p.sum() == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(real, p, rtol=1e-9)
        assert real.sum() == pytest.approx(1.0, abs=1e-9)

    # polar: the group-mean curve at 0 and 90 degrees is the mean of the stored E_x, E_y
    panel.plots.group_box.setCurrentIndex(0)
    theta, e = panel.plots.polar_curve()
    ok = [r for r in rows if r["set"] == 0 and r["status"] == "ok"]
    assert theta[0] == 0 and e[0] == e[-1]
    assert e[0] == pytest.approx(np.mean([r["E_x"] / r["E_s"] for r in ok]), rel=1e-9)
    # 180 angles: index 45 is 90 degrees
    assert e[45] == pytest.approx(np.mean([r["E_y"] / r["E_s"] for r in ok]), rel=1e-9)
    panel.plots.sample_spin.setValue(1)
    r1 = [r for r in rows if r["set"] == 0][1]
    theta, e = panel.plots.polar_curve()
    assert e[0] == pytest.approx(r1["E_x"] / r1["E_s"], rel=1e-9)


def test_cancel_kills_the_run_and_resume_finishes_without_duplicates(qtbot, panel, tmp_path):
    out = tmp_path / "study.csv"
    # 24 samples: after the first row there are seconds of work left to cancel
    _fill(panel, out, n=12, size="10x10", resolution=20)
    assert panel.run()
    qtbot.waitUntil(lambda: panel.progress.value() >= 1, timeout=60000)
    panel.watch_processes()
    assert panel.is_running
    panel.cancel()
    assert not panel.cancel_button.isEnabled()
    code = _wait_finished(qtbot, panel, timeout=30000)
    assert code == 130, panel.error_log.toPlainText()
    assert "Cancelled" in panel.status.text()
    kept = read_study(out)
    assert 1 <= len(kept) < 24

    assert panel.resume()
    assert _wait_finished(qtbot, panel) == 0, panel.error_log.toPlainText()
    rows = read_study(out)
    assert len(rows) == 24
    assert sorted((r["set"], r["index"]) for r in rows) == \
        [(j, i) for j in (0, 1) for i in range(12)]
    assert len({r["seed"] for r in rows}) == 24
    # the rows written before the cancel are kept as they were
    again = {(r["set"], r["index"]): r for r in rows}
    for r in kept:
        assert again[(r["set"], r["index"])]["C11"] == r["C11"]
    assert panel.last_summary["n_resumed"] == len(kept)
    assert [len(pts) for _, pts in panel.plots.scatter_points()] == \
        [sum(r["status"] == "ok" and r["set"] == j for r in rows) for j in (0, 1)]


def test_bad_hint_is_refused_before_launch(panel, tmp_path):
    _fill(panel, tmp_path / "s.csv", groups="T=1,L=1\nT=1,X=2")
    assert not panel.run()
    assert not panel.is_running and panel.process_id() is None
    text = panel.status.text()
    assert "hint group 2 'T=1,X=2'" in text and "'X' is not a block" in text
    assert not (tmp_path / "s.csv").exists()
    _fill(panel, "", groups="T=1")
    assert not panel.resume() and "Database" in panel.status.text()


def test_failed_study_shows_exit_code_and_stderr(qtbot, panel, tmp_path):
    out = tmp_path / "s.csv"
    out.write_text("not,a,study\n1,2,3\n")        # resuming it is refused by the engine
    _fill(panel, out, n=1)
    assert panel.resume()
    assert _wait_finished(qtbot, panel, timeout=60000) == 2
    assert "exit code 2" in panel.status.text()
    assert "mesoforge study:" in panel.error_log.toPlainText()
    assert panel.error_log.isVisible()


def test_open_database_plots_a_sweep_file(panel, tmp_path):
    out = tmp_path / "db.csv"
    sweep_hints("TL+-", n_hint_sets=3, samples_per_set=2, min_distance=0.1, seed=2,
                out_path=out, scheduler="synchronous", shape=(5, 5), resolution=10)
    rows = read_study(out)
    panel.ask_open_path = lambda: str(out)
    panel.open_button.click()
    assert "6 rows in 3 hint groups" in panel.status.text()
    pts = panel.plots.scatter_points()
    assert [len(p) for _, p in pts] == \
        [sum(r["status"] == "ok" and r["set"] == j for r in rows) for j in range(3)]
    for (_label, req, _real), j in zip(panel.plots.pie_fractions(), range(3)):
        np.testing.assert_allclose(req, [rows[2 * j][f"hint_{b}"] for b in BLOCKS], rtol=1e-9)
    bad = tmp_path / "bad.txt"
    bad.write_text("x")
    assert not panel.load_database(bad)
    assert "must end" in panel.status.text() or ".csv or .parquet" in panel.status.text()
    assert len(panel.plots.scatter_points()) == 3          # the plots are left as they were


def test_shutdown_stops_a_running_study(qtbot, panel, tmp_path):
    _fill(panel, tmp_path / "s.csv", n=50)
    finished = []
    panel.study_finished.connect(finished.append)
    assert panel.run()
    qtbot.waitUntil(lambda: bool(panel.process_id()), timeout=10000)   # started, maybe importing
    panel.watch_processes()
    panel.shutdown()
    assert not panel.is_running and finished and finished[0] != 0
    assert panel.run_button.isEnabled()
