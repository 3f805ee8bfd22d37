"""The Qt viewer (the only package that imports qtpy, pyvista and pyvistaqt)."""

from .main_window import MainWindow

__all__ = ["MainWindow"]
