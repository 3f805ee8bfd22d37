"""Images of a distance between two shapes, rendered by the viewer's own scene.

Panels side by side in one PNG: mesh A with the picked vertex, then mesh B coloured by
a distance from that vertex with its best match marked.  Each panel is drawn by the
off-screen main window (the same scene, colours, marker and colour bar as the viewer's
distance display) and captioned.  Used by ``modalviewer distance A --to B -o fig.png``
and ``scripts/hand_correspondence.py``.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class Panel:
    """One view: ``mesh`` coloured by ``distances`` (None: plain) with ``marker`` shown,
    seen from the viewer's default direction turned by ``azimuth`` and ``elevation``.

    display: "continuous" or "threshold" (blue where the distance is at most
    ``threshold`` times its largest value); kind: "vibration" | "feature" | "hks".
    """

    mesh: object
    title: str
    marker: int | None = None
    distances: np.ndarray | None = None
    kind: str = "vibration"
    display: str = "continuous"
    threshold: float = 0.2
    azimuth: float = 0.0  # degrees, added to the viewer's default view
    elevation: float = 0.0


def _caption(img: np.ndarray, text: str) -> np.ndarray:
    from PIL import Image, ImageDraw, ImageFont

    height = max(24, img.shape[0] // 20)
    band = Image.new("RGB", (img.shape[1], height), "white")
    draw = ImageDraw.Draw(band)
    try:
        font = ImageFont.load_default(size=int(height * 0.6))
    except TypeError:  # Pillow < 10.1: a fixed bitmap font
        font = ImageFont.load_default()
    draw.text((8, height // 6), text, fill="black", font=font)
    return np.vstack([np.asarray(band), img[:, :, :3]])


def render_panels(panels: list[Panel], path, size=(640, 560), window=None) -> Path:
    """Render ``panels`` left to right into one PNG at ``path`` (written atomically).

    ``window``: an off-screen main window to reuse (``cli._window``); made if None.
    """
    from PIL import Image

    from .cli import _window

    win = window if window is not None else _window(size)[1]
    images = []
    try:
        for panel in panels:
            win.set_mesh(panel.mesh)
            if panel.azimuth or panel.elevation:
                win.plotter.camera.Azimuth(panel.azimuth)
                win.plotter.camera.Elevation(panel.elevation)
                win.plotter.camera.OrthogonalizeViewUp()
                win.plotter.reset_camera()
            if panel.distances is not None:
                d = np.asarray(panel.distances, dtype=np.float64)
                if d.shape != (panel.mesh.n_vertices,):
                    raise ValueError("a panel's distances must have one value per vertex")
                win.last_distance = d
                win.distance_kind = panel.kind
                win.distance_display = panel.display
                win.threshold_fraction = float(panel.threshold)
                win.display = "distance"
                win._draw_distance()  # the viewer's own distance display, colour bar included
            win.scene.show_marker(panel.marker)
            images.append(_caption(win.viewport.render_now(), panel.title))
    finally:
        if window is None:
            win.close()
    height = max(img.shape[0] for img in images)
    canvas = np.full((height, sum(img.shape[1] for img in images), 3), 255, np.uint8)
    x = 0
    for img in images:
        canvas[: img.shape[0], x : x + img.shape[1]] = img
        x += img.shape[1]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".png", dir=path.parent)
    os.close(fd)
    try:
        Image.fromarray(canvas).save(tmp, format="PNG")
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
