"""Where VTK renders: the one place that decides between a display and off-screen EGL."""

from __future__ import annotations

import os
import sys


def has_display() -> bool:
    """True where windows can be shown: always off Linux; on Linux with ``DISPLAY`` or
    ``WAYLAND_DISPLAY`` set."""
    if sys.platform != "linux":
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def prepare_offscreen() -> None:
    """Without a display, let VTK render through EGL directly (instead of trying X first
    and failing); call before the first render window is made.  A choice already in
    ``VTK_DEFAULT_OPENGL_WINDOW`` is kept."""
    if not has_display():
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
