"""Pixel measurements of a rendered scene: how white the zero band is, how saturated the
colours are (a rendered ``modalviewer.scene.mesh_scene.MeshScene``).  Used by the tests
and by ``scripts/measure_render_style.py``.

The zero band is found by rendering the same view a second time with lighting off and a
flat indicator field (green: zero band facing the viewer, red: the rest of the surface),
so the measurement needs no knowledge of where the mesh lands on the screen.
"""

from __future__ import annotations

import numpy as np


def _flat_render(scene, indicator: np.ndarray) -> np.ndarray:
    """Render the scene with the surface coloured flat: 1 -> green, 0 -> red, lines hidden."""
    from modalviewer.scene.colors import lookup_table

    actor, mapper = scene.surface_actor, scene._mapper
    prop = actor.GetProperty()
    saved_field = np.array(scene.surface.point_data["field"])
    saved = (
        mapper.GetLookupTable(),
        mapper.GetScalarRange(),
        bool(mapper.GetScalarVisibility()),
        bool(prop.GetLighting()),
        prop.GetInterpolation(),
    )
    hidden = []
    for attr in ("iso_actor", "zero_actor", "marker_actor", "overlay_actor"):
        a = getattr(scene, attr, None)
        if a is not None and a.GetVisibility():
            a.SetVisibility(False)
            hidden.append(a)
    try:
        scene.surface.point_data["field"] = indicator.astype(np.float64)
        mapper.SetLookupTable(
            lookup_table([np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])], n=2)
        )
        mapper.SetScalarRange(0.0, 1.0)
        mapper.ScalarVisibilityOn()
        prop.SetLighting(False)
        plotter = scene.plotter
        plotter.render()
        img = np.asarray(plotter.screenshot(None, return_img=True))[:, :, :3]
    finally:
        scene.surface.point_data["field"] = saved_field
        mapper.SetLookupTable(saved[0])
        mapper.SetScalarRange(*saved[1])
        mapper.SetScalarVisibility(saved[2])
        prop.SetLighting(saved[3])
        prop.SetInterpolation(saved[4])
        for a in hidden:
            a.SetVisibility(True)
    return img


def facing(scene, cos_min: float = 0.7) -> np.ndarray:
    """(n,) bool: vertices whose normal makes an angle below acos(cos_min) with the
    direction to the camera."""
    cam = np.array(scene.plotter.camera.GetPosition())
    p = np.asarray(scene.surface.points)
    to_cam = cam - p
    to_cam /= np.linalg.norm(to_cam, axis=1, keepdims=True)
    return np.einsum("ij,ij->i", scene.normals, to_cam) > cos_min


def zero_band_masks(scene, field: np.ndarray, band: float = 0.05, cos_min: float = 0.7):
    """(mesh pixels, zero-band pixels facing the viewer) as (h, w) bool masks of the
    current view.  The zero band: |field| < band * max |field|."""
    field = np.asarray(field, dtype=np.float64)
    a = float(np.max(np.abs(field))) or 1.0
    indicator = (np.abs(field) < band * a) & facing(scene, cos_min)
    img = _flat_render(scene, indicator).astype(int)
    r, g, b = img[:, :, 0], img[:, :, 1], img[:, :, 2]
    green = (g > 250) & (r < 5) & (b < 5)
    red = (r > 250) & (g < 5) & (b < 5)
    # shrink the band by one pixel: its border pixels mix with isoline anti-aliasing
    inner = green.copy()
    inner[1:, :] &= green[:-1, :]
    inner[:-1, :] &= green[1:, :]
    inner[:, 1:] &= green[:, :-1]
    inner[:, :-1] &= green[:, 1:]
    return green | red, inner


def white_level(img: np.ndarray, mask: np.ndarray) -> dict:
    """Percentiles (5, 50, 95) of min(R, G, B) over the pixels in ``mask``."""
    m = np.min(img[:, :, :3].astype(int), axis=2)[mask]
    if m.size == 0:
        return {"n": 0, "p5": float("nan"), "p50": float("nan"), "p95": float("nan")}
    p5, p50, p95 = np.percentile(m, [5, 50, 95])
    return {"n": int(m.size), "p5": float(p5), "p50": float(p50), "p95": float(p95)}


def saturation(img: np.ndarray, mesh: np.ndarray) -> dict:
    """Shares of mesh pixels that are clearly blue (blue 60 above red) and clearly orange
    (red 80 above blue)."""
    r, g, b = (img[:, :, i].astype(int) for i in range(3))
    n = max(int(mesh.sum()), 1)
    blue = (b > r + 60) & mesh
    orange = (r > b + 80) & mesh
    return {"blue": blue.sum() / n, "orange": orange.sum() / n}
