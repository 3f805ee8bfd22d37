"""Dock panels: each observes the viewer state and sets it on input; what needs a
computation it asks of the viewer."""
