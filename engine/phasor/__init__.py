"""Phasor infill (Tricard et al.): control fields, phasor-noise kernels,
phase alignment, filtered evaluation and singularity analysis."""
