"""Batch runs: property studies and hint databases on Dask.

A local cluster by default; the same code with a scheduler address scales
out. Rows are appended to a CSV file as results arrive and an interrupted
run resumes from what it wrote (``engine.batch.study``). A file that is not
a study file, or holds another study, is refused with ``StudyFileError`` and
left as it was (``engine.batch.study_file``).
"""

from .hints_text import format_hints, parse_hints
from .rows import RowFile, StudyFileError, read_rows
from .runner import SYNCHRONOUS, run_samples
from .sample import Sample, StudyConfig, columns, evaluate_sample, sample_seed
from .study import make_config, read_study, run_study, summarise_rows, sweep_hints
from .study_file import read_params

__all__ = [
    "run_study", "sweep_hints", "read_study", "summarise_rows", "make_config",
    "parse_hints", "format_hints", "RowFile", "read_rows", "run_samples", "SYNCHRONOUS",
    "Sample", "StudyConfig", "columns", "evaluate_sample", "sample_seed", "StudyFileError",
    "read_params",
]
