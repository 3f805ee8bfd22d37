"""Images of a distance between two shapes (``modalviewer distance A --to B -o``): mesh
A with the picked vertex beside mesh B coloured by the distance from it, each panel
drawn off screen by the viewer's :class:`~modalviewer.scene.mesh_scene.MeshScene`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .viewer.state import DEFAULT_THRESHOLD_FRACTION


@dataclass
class Panel:
    """One view: ``mesh`` coloured by ``distances`` (None: plain) with ``marker`` shown,
    seen from the viewer's default direction turned by ``azimuth`` and ``elevation``;
    ``display`` "continuous" or "threshold" (blue up to ``threshold`` times the largest)."""

    mesh: object
    title: str
    marker: int | None = None
    distances: np.ndarray | None = None
    display: str = "continuous"
    threshold: float = DEFAULT_THRESHOLD_FRACTION
    azimuth: float = 0.0  # degrees about the up axis, from the viewer's first view
    elevation: float = 0.0
    face_marker: bool = False  # turned about the up axis so the marker faces the camera
    colorbar: str | None = None  # the colour bar's title (a two-swatch legend on a threshold map)


def render_panel(panel: Panel, size=(640, 560)) -> np.ndarray:
    """(h, w, 3) image of one panel, captioned."""
    from .scene.comparison import caption
    from .scene.export import grab
    from .scene.mesh_scene import MeshScene
    from .scene.offscreen import offscreen_plotter
    from .viewer.camera import Camera

    plotter = offscreen_plotter(size)
    try:
        scene = MeshScene(plotter, panel.mesh)  # its own vertex normals
        if panel.distances is not None:
            d = np.asarray(panel.distances, dtype=np.float64)
            if d.shape != (panel.mesh.n_vertices,):
                raise ValueError("a panel's distances must have one value per vertex")
            thr = panel.threshold * float(d.max())
            if panel.display == "threshold":
                scene.show_threshold(d, thr, name="threshold")
            else:
                scene.show_field(d, "sequential", name="distance")
            if panel.colorbar:  # the labels name a threshold map's two swatches
                labels = [f"{panel.colorbar} <= {thr:.3g}", "the rest"]
                scene.set_colorbar(panel.colorbar, labels=labels)
        scene.show_marker(panel.marker)
        # the viewer's first view of the mesh, turned about its up axis by ``azimuth``
        # (or until the marker faces the camera) and tilted by ``elevation``
        first = scene.canonical_camera()
        scene.set_camera(first)
        camera = plotter.camera
        azimuth = panel.azimuth
        if panel.face_marker and panel.marker is not None:
            to_camera = np.asarray(first.direction)
            up = np.asarray(first.up)
            n = scene.normals[panel.marker] - np.dot(scene.normals[panel.marker], up) * up
            if np.linalg.norm(n) > 0.3:
                side = np.cross(up, to_camera)
                azimuth = float(np.degrees(np.arctan2(np.dot(n, side), np.dot(n, to_camera))))
        camera.Azimuth(azimuth)
        camera.Elevation(panel.elevation)
        camera.OrthogonalizeViewUp()
        scene.set_camera(
            Camera(tuple(camera.position), tuple(camera.focal_point), tuple(camera.up))
        )
        image = grab(plotter, scene)[:, :, :3]
    finally:
        plotter.close()
    return caption(image, panel.title)


def render_panels(panels: list[Panel], path, size=(640, 560)) -> Path:
    """Render ``panels`` left to right, each ``size`` pixels, into one PNG at ``path``
    (written atomically)."""
    from .scene.export import save_png, side_by_side

    return save_png(path, side_by_side([render_panel(panel, size) for panel in panels]))
