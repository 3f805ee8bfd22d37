"""Writing screenshots and per-vertex fields atomically (temporary file, then rename)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from ..core.mesh import Mesh


def _temp_beside(path: Path) -> Path:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    return Path(tmp)


def _check_folder(path: Path) -> None:
    folder = path.parent
    if not folder.exists():
        folder.mkdir(parents=True, exist_ok=True)
    if not os.access(folder, os.W_OK):
        raise OSError(f"the folder {folder} is not writable; choose another one")


def save_screenshot(viewport, path: Path, scale: int = 1, transparent: bool = False) -> Path:
    """Render the viewport's plotter to a PNG at ``scale`` times its size."""
    from PIL import Image

    path = Path(path)
    if path.suffix.lower() != ".png":
        path = path.with_suffix(".png")
    _check_folder(path)
    plotter = viewport.plotter
    scale = int(max(1, scale))
    plotter.render()  # pyvista's screenshot reads the last frame; make it the current scene
    img = plotter.screenshot(None, transparent_background=transparent, return_img=True, scale=scale)
    img = np.ascontiguousarray(img)
    tmp = _temp_beside(path)
    try:
        Image.fromarray(img).save(tmp, format="PNG")
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def save_field_mesh(path: Path, mesh: Mesh, fields: dict[str, np.ndarray]) -> Path:
    """Write the mesh with per-vertex ``fields`` as point data to .vtp or .ply."""
    import pyvista as pv

    path = Path(path)
    if path.suffix.lower() not in (".vtp", ".ply"):
        raise ValueError("per-vertex fields are exported as .vtp or .ply")
    _check_folder(path)
    faces = np.hstack([np.full((mesh.n_faces, 1), 3), mesh.faces]).ravel()
    poly = pv.PolyData(np.array(mesh.vertices), faces)
    for name, values in fields.items():
        poly.point_data[name] = np.asarray(values)
    tmp = _temp_beside(path)
    try:
        poly.save(tmp, binary=True)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path
