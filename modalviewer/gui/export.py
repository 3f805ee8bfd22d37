"""Writing screenshots and per-vertex fields atomically (temporary file, then rename),
with the permissions of the user's umask."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from ..core.files import atomic_write
from ..core.mesh import Mesh


def _check_folder(path: Path) -> None:
    folder = path.parent
    if not folder.exists():
        folder.mkdir(parents=True, exist_ok=True)
    if not os.access(folder, os.W_OK):
        raise OSError(f"the folder {folder} is not writable; choose another one")


def save_screenshot(
    viewport,
    path: Path,
    scale: int = 1,
    transparent: bool = False,
    legend: bool = True,
    colorbar: bool | None = None,
    scene=None,
) -> Path:
    """Render the viewport's plotter to a PNG at ``scale`` times its size.

    The scene's legend (if ``legend`` and the scene has one) and colour bar (as shown on
    screen when ``colorbar`` is None, else forced on or off; a two-swatch legend for
    threshold maps) are drawn onto the image at the same scale, also on a transparent
    background.  ``scene`` defaults to the scene drawn on the viewport's plotter."""
    from PIL import Image

    from .overlay import draw_overlay

    path = Path(path)
    if path.suffix.lower() != ".png":
        path = path.with_suffix(".png")
    _check_folder(path)
    plotter = viewport.plotter
    scale = int(max(1, scale))
    if scene is None:
        scene = getattr(plotter, "_modalviewer_scene", None)
    overlay = scene.overlay(legend=legend, colorbar=colorbar) if scene is not None else None
    # the scene's own 2D actors are replaced by the overlay drawn at the export's scale
    hidden = [a for a in scene.overlay_actors() if a.GetVisibility()] if scene else []
    for actor in hidden:
        actor.SetVisibility(False)
    try:
        plotter.render()  # pyvista's screenshot reads the last frame: the current scene
        img = plotter.screenshot(
            None, transparent_background=transparent, return_img=True, scale=scale
        )
    finally:
        for actor in hidden:
            actor.SetVisibility(True)
        if hidden:
            plotter.render()
    img = np.ascontiguousarray(img)
    if overlay:
        img = draw_overlay(img, overlay, scale * getattr(scene, "overlay_scale", 1.0))
    atomic_write(path, lambda tmp: Image.fromarray(img).save(tmp, format="PNG"))
    return path


def save_field_mesh(path: Path, mesh: Mesh, fields: dict[str, np.ndarray]) -> Path:
    """Write the mesh with per-vertex ``fields`` as point data to .vtp or .ply.

    The points are the mesh's: the file's vertices in the file's order, less those no
    face uses (merged duplicates once).  Where that numbering differs from the file's,
    a point-data array ``file_vertex`` gives each point's vertex number in the file."""
    import pyvista as pv

    path = Path(path)
    if path.suffix.lower() not in (".vtp", ".ply"):
        raise ValueError("per-vertex fields are exported as .vtp or .ply")
    _check_folder(path)
    faces = np.hstack([np.full((mesh.n_faces, 1), 3), mesh.faces]).ravel()
    poly = pv.PolyData(np.array(mesh.vertices), faces)
    for name, values in fields.items():
        poly.point_data[array_name(name)] = np.asarray(values)
    if mesh.renumbered:
        poly.point_data["file_vertex"] = np.asarray(mesh.file_vertices)
    return atomic_write(path, lambda tmp: poly.save(tmp, binary=True))


def array_name(title: str) -> str:
    """A point-data array name made of a picture's title: letters, digits, "_", "-" and
    "." only.  VTK writes the name into XML unescaped, and a "<" ("Vibration distance <
    0.0104") made a .vtp file no reader opens."""
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", title).strip("_")
    return name or "field"
