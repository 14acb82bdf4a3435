"""Implicit multiscale media (paper 004): SDF particle clouds, agglomerates,
piles and periodic functions as trees of `values.SDF`, evaluated in numpy and
compiled to GLSL from the same tree."""
