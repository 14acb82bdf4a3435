"""Reaction/diffusion lattice synthesis (Garnier, Schmidt & Rohmer): inputs, growth, compilation."""
