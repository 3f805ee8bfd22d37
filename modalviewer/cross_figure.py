"""Images of a distance between two shapes, rendered by the viewer's own scene.

Panels side by side in one PNG: mesh A with the picked vertex, then mesh B coloured by
a distance from that vertex with its best match marked.  Each panel is drawn off-screen
by the viewer's :class:`~modalviewer.scene.mesh_scene.MeshScene` (the same surface, colour
maps and marker as the viewer's distance display: white = similar, red = the largest
distance; or blue where the distance is below the threshold) and captioned.  Used by
``modalviewer distance A --to B -o fig.png`` and ``scripts/hand_correspondence.py``.
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
    ``threshold`` times its largest value).
    """

    mesh: object
    title: str
    marker: int | None = None
    distances: np.ndarray | None = None
    display: str = "continuous"
    threshold: float = 0.2
    azimuth: float = 0.0  # degrees, added to the viewer's default view
    elevation: float = 0.0
    face_marker: bool = False  # turned about y so the marker faces the camera


def _caption(img: np.ndarray, text: str) -> np.ndarray:
    from PIL import Image, ImageDraw, ImageFont

    height = max(24, img.shape[0] // 20)
    band = Image.new("RGB", (img.shape[1], height), "white")
    draw = ImageDraw.Draw(band)
    size = int(height * 0.6)
    try:
        font = ImageFont.load_default(size=size)
        while size > 8 and draw.textlength(text, font=font) > img.shape[1] - 16:
            size -= 1
            font = ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: a fixed bitmap font
        font = ImageFont.load_default()
    draw.text((8, height // 6), text, fill="black", font=font)
    return np.vstack([np.asarray(band), img[:, :, :3]])


def _plotter(size):
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista as pv

    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    plotter.set_background("white")
    return plotter


def render_panel(panel: Panel, size=(640, 560)) -> np.ndarray:
    """(h, w, 3) image of one panel, captioned."""
    from .core.laplacian import vertex_normals
    from .scene.mesh_scene import MeshScene

    plotter = _plotter(size)
    try:
        normals = vertex_normals(panel.mesh)
        scene = MeshScene(plotter, panel.mesh, normals)
        if panel.distances is not None:
            d = np.asarray(panel.distances, dtype=np.float64)
            if d.shape != (panel.mesh.n_vertices,):
                raise ValueError("a panel's distances must have one value per vertex")
            if panel.display == "threshold":
                thr = panel.threshold * float(d.max())
                scene.show_threshold(d, thr, name="threshold")
            else:
                scene.show_field(d, "sequential", isolines=0, name="distance")
        scene.show_marker(panel.marker)
        # the viewer's first view: looking down -z, y up, turned a little
        azimuth, elevation = 25.0 + panel.azimuth, 15.0 + panel.elevation
        if panel.face_marker and panel.marker is not None:
            # turn about the y axis until the marker's normal points at the camera (a
            # normal along y, like a fingertip's, is seen from the default view)
            nx, _, nz = normals[panel.marker]
            if np.hypot(nx, nz) > 0.3:
                azimuth = float(np.degrees(np.arctan2(nx, nz)))
        plotter.view_xy()
        plotter.camera.Azimuth(azimuth)
        plotter.camera.Elevation(elevation)
        plotter.camera.OrthogonalizeViewUp()
        plotter.reset_camera()
        plotter.render()
        image = np.asarray(plotter.screenshot(None, return_img=True))[:, :, :3]
    finally:
        plotter.close()
    return _caption(image, panel.title)


def render_panels(panels: list[Panel], path, size=(640, 560)) -> Path:
    """Render ``panels`` left to right, each ``size`` pixels, into one PNG at ``path``
    (written atomically)."""
    from PIL import Image

    images = [render_panel(panel, size) for panel in panels]
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
