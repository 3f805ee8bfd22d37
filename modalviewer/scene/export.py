"""Pictures and per-vertex fields written atomically (temporary file, then rename),
with the permissions of the user's umask."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..core.files import atomic_write, make_folder_for
from ..core.mesh import Mesh


def grab(
    plotter,
    scene=None,
    scale: int = 1,
    transparent: bool = False,
    legend: bool = True,
    colorbar: bool | None = None,
    marker: bool = True,
) -> np.ndarray:
    """The plotter's view at ``scale`` times its size, (h, w, 3 or 4) uint8, with ``scene``'s
    (default the plotter's) legend and colour bar (None: as on screen) drawn at that scale."""
    from .overlay import draw_overlay

    scale = int(max(1, scale))
    scene = scene or getattr(plotter, "_modalviewer_scene", None)
    overlay = scene.overlay(legend=legend, colorbar=colorbar) if scene is not None else None
    # the scene's own overlay is replaced by the overlay drawn at the export's scale
    hidden = [] if scene is None else [scene.overlay_actor, None if marker else scene.marker_actor]
    hidden = [actor for actor in hidden if actor is not None and actor.GetVisibility()]
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
    return draw_overlay(img, overlay, scale * getattr(scene, "overlay_scale", 1.0))


def side_by_side(images: list[np.ndarray], gap: int = 0, transparent: bool = False):
    """``images`` left to right on one canvas (white, or transparent), ``gap`` pixels
    apart, aligned at the top."""
    channels = 4 if transparent else 3
    height = max(img.shape[0] for img in images)
    width = sum(img.shape[1] for img in images) + gap * (len(images) - 1)
    canvas = np.full((height, width, channels), 0 if transparent else 255, np.uint8)
    x = 0
    for img in images:
        if img.shape[2] < channels:
            img = np.dstack([img, np.full(img.shape[:2], 255, np.uint8)])
        canvas[: img.shape[0], x : x + img.shape[1]] = img[:, :, :channels]
        x += img.shape[1] + gap
    return canvas


OTHER_PICTURE_SUFFIXES = (".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".gif", ".webp", ".pdf")
OTHER_PICTURE_SUFFIXES += (".svg", ".eps")
"""Suffixes of picture formats other than PNG: a name ending in one is refused, where
PNG data under it would mislead."""


def png_path(path) -> Path:
    """``path`` as the PNG to write, its folder created and checked writable: a name
    ending in .png as it is, a name without a picture suffix with ".png" added
    (``fig_t0.5`` -> ``fig_t0.5.png``); ValueError for another picture format's suffix
    (:data:`OTHER_PICTURE_SUFFIXES`)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix in OTHER_PICTURE_SUFFIXES:
        raise ValueError(f"{path.name}: pictures are written as PNG; give a name ending in .png")
    if suffix != ".png":
        path = path.with_name(path.name + ".png")
    make_folder_for(path)
    return path


def save_png(path, img: np.ndarray) -> Path:
    """Write ``img`` to ``path`` (.png added if missing) atomically; returns the path."""
    from PIL import Image

    path = png_path(path)
    atomic_write(path, lambda tmp: Image.fromarray(img).save(tmp, format="PNG"))
    return path


def save_field_mesh(path: Path, mesh: Mesh, fields: dict[str, np.ndarray]) -> Path:
    """Write the mesh with per-vertex ``fields`` to .vtp or .ply, one point per input vertex
    (and ``file_vertex``, each point's input number, where the solver renumbered)."""
    from ..interop import to_pyvista

    path = Path(path)
    if path.suffix.lower() not in (".vtp", ".ply"):
        raise ValueError("per-vertex fields are exported as .vtp or .ply")
    make_folder_for(path)
    arrays = {array_name(name): np.asarray(values) for name, values in fields.items()}
    if mesh.renumbered:
        arrays["file_vertex"] = np.asarray(mesh.file_vertices)
    if path.suffix.lower() == ".ply":
        return atomic_write(path, lambda tmp: _write_ply(tmp, mesh, arrays))
    poly = to_pyvista(mesh, fields=arrays)
    return atomic_write(path, lambda tmp: poly.save(tmp, binary=True))


def _write_ply(path: Path, mesh: Mesh, arrays: dict[str, np.ndarray]) -> None:
    """Binary little-endian PLY of ``mesh`` with each of ``arrays`` (n,) or (n, c) as
    vertex properties (``name``, or ``name_0 .. name_c-1``; doubles, integers as int),
    which VTK's PLY writer would drop (it keeps only colours and texture coordinates)."""
    columns = [(c, "<f8", mesh.vertices[:, i]) for i, c in enumerate("xyz")]
    for name, values in arrays.items():
        kind = "<i4" if np.issubdtype(values.dtype, np.integer) else "<f8"
        if values.ndim == 1:
            columns.append((name, kind, values))
        else:
            columns += [(f"{name}_{j}", kind, values[:, j]) for j in range(values.shape[1])]
    ply_type = {"<f8": "double", "<i4": "int"}
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {mesh.n_vertices}"]
    header += [f"property {ply_type[kind]} {name}" for name, kind, _ in columns]
    header += [f"element face {mesh.n_faces}", "property list uchar int vertex_indices"]
    header.append("end_header")
    vertices = np.empty(mesh.n_vertices, dtype=[(name, kind) for name, kind, _ in columns])
    for name, _, values in columns:
        vertices[name] = values
    faces = np.empty(mesh.n_faces, dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"], faces["i"] = 3, mesh.faces
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(vertices.tobytes())
        f.write(faces.tobytes())


def array_name(title: str) -> str:
    """A point-data array name made of a picture's title: letters, digits, "_", "-" and
    "." only.  VTK writes the name into XML unescaped, and a "<" ("Vibration distance <
    0.0104") made a .vtp file no reader opens."""
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", title).strip("_")
    return name or "field"
