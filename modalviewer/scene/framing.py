"""Fitting a picture's camera to its shape: the whole shape (deformed, or over a whole
vibration) inside the frame and clear of the legend above it and the colour bar below,
whatever the picture's width and height.  No Qt."""

from __future__ import annotations

import numpy as np

MARGIN = 0.03
"""Free space left around the shape, as a share of the picture's width and height."""

FIT_STEPS = 6
"""Pan-and-dolly steps of :func:`fit_points` (perspective makes one step inexact)."""


def overlay_boxes(width: int, height: int, overlay, scale: float = 1.0):
    """((legend width, legend height), colour bar height) in pixels, measured on a blank
    image drawn by :func:`.overlay.draw_overlay` (so any layout of theirs is followed)."""
    from .overlay import Overlay, draw_overlay

    legend, bottom = (0, 0), 0
    if overlay is None:
        return legend, bottom
    blank = np.zeros((int(height), int(width), 4), np.uint8)
    # each drawn alone on a blank image (one without a legend or bar stays blank)
    alpha = draw_overlay(blank, Overlay(overlay.legend, None), scale)[..., 3]
    rows, cols = np.flatnonzero(alpha.any(1)), np.flatnonzero(alpha.any(0))
    if rows.size:
        legend = (int(cols.max()) + 1, int(rows.max()) + 1)
    alpha = draw_overlay(blank, Overlay(None, overlay.colorbar), scale)[..., 3]
    rows = np.flatnonzero(alpha.any(1))
    if rows.size:
        bottom = int(height) - int(rows.min())
    return legend, bottom


def project(camera, points: np.ndarray, aspect: float) -> np.ndarray:
    """(m, 2) normalised device coordinates (-1 .. 1 across the picture) of ``points``."""
    m = camera.GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0)
    matrix = np.array([[m.GetElement(i, j) for j in range(4)] for i in range(4)])
    p = np.column_stack([points, np.ones(len(points))]) @ matrix.T
    return p[:, :2] / p[:, 3:4]


def fit_clear_of_overlay(renderer, points, size, overlay, scale: float = 1.0) -> None:
    """:func:`fit_points` into the larger of the two free parts of the picture: below the
    legend, or right of it, both above the colour bar."""
    w, h = (int(size[0]), int(size[1]))
    (lw, lh), bottom = overlay_boxes(w, h, overlay, scale)
    boxes = [(0, lh, 0, bottom)]
    if lw and lw < 0.6 * w:
        boxes.append((lw, 0, 0, bottom))
    best = None
    for box in boxes:
        fit_points(renderer, points, (w, h), *box)
        camera = renderer.GetActiveCamera()
        reach = (
            camera.GetParallelScale() if camera.GetParallelProjection() else camera.GetDistance()
        )
        if best is None or reach < best[0]:
            best = (reach, box)
    if len(boxes) > 1 and best[1] != boxes[-1]:
        fit_points(renderer, points, (w, h), *best[1])


def fit_points(
    renderer, points: np.ndarray, size, left: int = 0, top: int = 0, right: int = 0, bottom: int = 0
) -> None:
    """Pan and dolly the camera, keeping its direction, so that ``points`` fill ``size``
    less the pixels at ``left`` ... ``bottom`` and :data:`MARGIN`."""
    w, h = (int(size[0]), int(size[1]))
    points = np.asarray(points, dtype=np.float64)
    if len(points) == 0 or w < 2 or h < 2:
        return
    view_angle_on_smaller_side(renderer)
    camera = renderer.GetActiveCamera()
    aspect, angle = w / h, camera.GetViewAngle()
    # the free box in normalised device coordinates
    x0 = -1.0 + 2.0 * (left / w + MARGIN)
    x1 = 1.0 - 2.0 * (right / w + MARGIN)
    y0 = -1.0 + 2.0 * (bottom / h + MARGIN)
    y1 = 1.0 - 2.0 * (top / h + MARGIN)
    if y1 - y0 < 0.2 or x1 - x0 < 0.2:  # a picture too small for its legend: use all of it
        x0 = y0 = -1.0 + 2.0 * MARGIN
        x1 = y1 = 1.0 - 2.0 * MARGIN
    lo, hi = points.min(0), points.max(0)
    centre = 0.5 * (lo + hi)
    direction = np.array(camera.GetDirectionOfProjection())
    distance = camera.GetDistance()
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(centre - distance * direction))
    renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
    for _ in range(FIT_STEPS):
        ndc = project(camera, points, aspect)
        (ax, ay), (bx, by) = ndc.min(0), ndc.max(0)
        k = max((bx - ax) / (x1 - x0), (by - ay) / (y1 - y0), 1e-6)
        dx = 0.5 * (x0 + x1) - 0.5 * (ax + bx)
        dy = 0.5 * (y0 + y1) - 0.5 * (ay + by)
        if abs(k - 1.0) < 1e-3 and abs(dx) < 1e-3 and abs(dy) < 1e-3:
            break
        # the world lengths of half the picture at the focal point
        focal, position = np.array(camera.GetFocalPoint()), np.array(camera.GetPosition())
        d = float(np.linalg.norm(focal - position))
        parallel = camera.GetParallelProjection()
        half = camera.GetParallelScale() if parallel else d * np.tan(np.radians(angle) / 2.0)
        if not parallel and camera.GetUseHorizontalViewAngle():
            half_w, half_h = half, half / aspect
        else:
            half_h, half_w = half, half * aspect
        up = np.array(camera.GetViewUp())
        forward = (focal - position) / d
        right = np.cross(forward, up)
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        shift = -dx * half_w * right - dy * half_h * up
        camera.SetFocalPoint(*(focal + shift))
        camera.SetPosition(*(position + shift))
        if parallel:
            camera.SetParallelScale(half * k)
        else:
            camera.Dolly(1.0 / k)
    renderer.ResetCameraClippingRange()


def view_angle_on_smaller_side(renderer) -> None:
    """Make the active camera's view angle apply to the smaller side of the view.

    VTK applies it to the height, so a view narrower than tall crops a mesh fitted in a
    wider one; on the smaller side, a camera fitted to the bounding sphere keeps the whole
    mesh in sight at any shape of the view.  Called before every render and before a fit."""
    w, h = renderer.GetSize()
    camera = renderer.GetActiveCamera()
    narrow = bool(w < h)
    if bool(camera.GetUseHorizontalViewAngle()) != narrow:
        camera.SetUseHorizontalViewAngle(narrow)


def fit_smaller_side(renderer) -> None:
    """Run :func:`view_angle_on_smaller_side` before every render of ``renderer``."""
    renderer.AddObserver("StartEvent", lambda *_: view_angle_on_smaller_side(renderer))
