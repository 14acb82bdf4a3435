"""Moved: see engine.progress (kept as an alias until every import is rewritten)."""

from engine.progress import *  # noqa: F401,F403
from engine.progress import _PARALLEL_LOCK, PARALLEL_LOCK, TARGET_CHUNK_SECONDS, Cancelled, ProgressFn, report, run_chunked, stage  # noqa: F401
