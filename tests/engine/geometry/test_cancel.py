"""Progress reporting and cooperative cancellation helpers."""

import pytest

from engine.geometry import Cancelled
from engine.progress import report, run_chunked


def test_report_semantics():
    report(None, 1, 2)                     # no callback: nothing happens
    report(lambda d, t: True, 1, 2)
    report(lambda d, t: None, 1, 2)        # forgetting to return does not cancel
    with pytest.raises(Cancelled):
        report(lambda d, t: False, 1, 2)


@pytest.mark.parametrize("with_progress", [False, True])
def test_run_chunked_covers_every_item_once_in_order(with_progress):
    seen, calls = [], []

    def work(a, b):
        seen.extend(range(a, b))

    def progress(done, total):
        calls.append((done, total))
        return True

    run_chunked(work, 37, progress if with_progress else None)
    assert seen == list(range(37))
    if with_progress:
        assert calls[0] == (0, 37) and calls[-1] == (37, 37)
        assert [d for d, _ in calls] == sorted(d for d, _ in calls)


def test_run_chunked_stops_when_asked():
    seen = []
    with pytest.raises(Cancelled):
        run_chunked(lambda a, b: seen.extend(range(a, b)), 100, lambda d, t: d < 5)
    assert 5 <= len(seen) < 100
