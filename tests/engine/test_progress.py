"""engine.progress: the one adaptive-chunk rule (next_chunk) and run_chunked's chunks under it."""

import pytest

import engine.progress as progress_module
from engine.progress import TARGET_CHUNK_SECONDS, next_chunk, run_chunked


def test_next_chunk_aims_at_the_target_growing_at_most_4x():
    per_item = TARGET_CHUNK_SECONDS / 100          # 100 items make one target chunk
    assert next_chunk(10, 10, 10 * per_item) == 40            # fast: 4x, not 10x
    assert next_chunk(50, 50, 50 * per_item) == 100           # within 4x: the rate's size
    assert next_chunk(400, 400, 400 * per_item) == 100        # slow: shrinks at once
    assert next_chunk(10, 10, 100.0) == 1                     # never below 1
    assert next_chunk(10, 10, 0.0) == 40                      # faster than the clock: 4x
    assert next_chunk(10, 10, 0.0, most=25) == 25             # a loop's own bound
    assert next_chunk(10, 5, 5 * per_item) == 40              # a chunk cut short: its rate counts


def test_run_chunked_chunks_follow_the_rule(monkeypatch):
    """A fake clock (each item costs 1 ms of it): the chunk sizes are the rule's, whatever the machine."""
    clock = [0.0]
    monkeypatch.setattr(progress_module.time, "perf_counter", lambda: clock[0])
    sizes = []

    def work(a, b):
        sizes.append(b - a)
        clock[0] += 1e-3 * (b - a)

    run_chunked(work, 300, lambda d, t: True, first_chunk=2)
    assert sum(sizes) == 300
    assert sizes[:3] == [2, 8, 32]                 # 4x at a time up to the target ...
    assert all(39 <= s <= 40 for s in sizes[3:-1])   # ... then 40 items of 1 ms (up to rounding)


@pytest.mark.parametrize("first", [1, 2, 7])
def test_run_chunked_without_a_clock_tick_grows_4x(monkeypatch, first):
    monkeypatch.setattr(progress_module.time, "perf_counter", lambda: 0.0)
    sizes = []
    run_chunked(lambda a, b: sizes.append(b - a), 1000, lambda d, t: True, first_chunk=first)
    assert sizes[0] == first and all(b == 4 * a for a, b in zip(sizes[:-2], sizes[1:-1]))
