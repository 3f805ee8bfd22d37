"""Dock panels: each observes the viewer state and sets it on input, nothing else."""
