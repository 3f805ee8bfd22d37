"""Cameras for a mesh, as plain numbers (no Qt, no VTK): the canonical first view and the
axis presets.

Canonical view: the up axis is the caller's (a file convention) or +Y, the convention of
most OBJ/PLY/OFF models.  Among the horizontal viewing directions (perpendicular to up,
every 5 degrees) the viewer looks along the one from which the surface shows the largest
silhouette (estimated from the projected vertices on a grid of 3 mean edge lengths),
preferring a coordinate axis when it shows at least 90 % of the best; if the view from
above shows more than ``TOP_VIEW_RATIO`` times that (a plate lying across the up axis),
it looks from above.  Then the camera turns by a small azimuth and elevation so the
view shows depth.  The camera sits on the side of +Z (then +X, then +Y) of its axis, the
side most models face.  Without faces the principal axis of least spread stands in for
the direction of the largest silhouette.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AXES = {
    "+x": (1.0, 0.0, 0.0),
    "-x": (-1.0, 0.0, 0.0),
    "+y": (0.0, 1.0, 0.0),
    "-y": (0.0, -1.0, 0.0),
    "+z": (0.0, 0.0, 1.0),
    "-z": (0.0, 0.0, -1.0),
}
PRESETS = ("+x", "-x", "+y", "-y", "+z", "-z", "isometric")
DEFAULT_UP = "+y"
VIEW_ANGLE = 30.0  # degrees, VTK's default
SNAP_DEGREES = 25.0
TOP_VIEW_RATIO = 1.5
AXIS_PREFERENCE = 0.9  # a coordinate axis showing this share of the best is taken
# which side of the viewing axis the camera sits on: the +Z side first (models face +Z)
_FRONT = np.array([0.1, 0.2, 1.0]) / np.linalg.norm([0.1, 0.2, 1.0])
_TURN_TOWARD = np.array([0.5, 0.0, 1.0])


@dataclass(frozen=True)
class Camera:
    """position, focal_point and up (unit, orthogonal to the viewing direction)."""

    position: tuple[float, float, float]
    focal_point: tuple[float, float, float]
    up: tuple[float, float, float]

    @property
    def direction(self) -> np.ndarray:
        """Unit vector from the focal point to the camera."""
        d = np.subtract(self.position, self.focal_point)
        return d / np.linalg.norm(d)

    def as_dict(self) -> dict:
        return {
            "position": list(self.position),
            "focal_point": list(self.focal_point),
            "view_up": list(self.up),
        }


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(v)
    if n == 0:
        raise ValueError("zero vector")
    return v / n


def _up_vector(up) -> np.ndarray:
    if up is None:
        up = DEFAULT_UP
    if isinstance(up, str):
        key = up.lower() if up[0] in "+-" else "+" + up.lower()
        if key not in AXES:
            raise ValueError(f"unknown up axis {up!r}; use one of {', '.join(AXES)}")
        return np.array(AXES[key])
    return _unit(up)


def _bounds(vertices) -> tuple[np.ndarray, float]:
    """(centre of the bounding box, half its diagonal)."""
    v = np.asarray(vertices, dtype=np.float64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    return 0.5 * (lo + hi), max(0.5 * float(np.linalg.norm(hi - lo)), 1e-12)


def principal_axes(vertices, faces=None) -> tuple[np.ndarray, np.ndarray]:
    """(variances (3,) descending, axes (3, 3) with the axes as rows) of the surface: the
    area-weighted second moments of the triangles (each triangle's own spread included),
    or of the vertices without faces."""
    v = np.asarray(vertices, dtype=np.float64)
    if faces is None or len(faces) == 0:
        c = v - v.mean(axis=0)
        cov = c.T @ c / max(len(v), 1)
    else:
        f = np.asarray(faces)
        x0, x1, x2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        area = 0.5 * np.linalg.norm(np.cross(x1 - x0, x2 - x0), axis=1)
        total = float(area.sum()) or 1.0
        w = area / total
        centroid = (x0 + x1 + x2) / 3.0
        mean = w @ centroid
        # exact second moment of a uniform triangle: (sum_i x_i x_i^T + s s^T) / 12 with
        # s = x0 + x1 + x2, taken about the surface's mean
        a, b, c = x0 - mean, x1 - mean, x2 - mean
        s = a + b + c
        second = (
            np.einsum("i,ij,ik->jk", w, a, a)
            + np.einsum("i,ij,ik->jk", w, b, b)
            + np.einsum("i,ij,ik->jk", w, c, c)
            + np.einsum("i,ij,ik->jk", w, s, s)
        ) / 12.0
        cov = second
    values, vectors = np.linalg.eigh(cov)
    order = np.argsort(values)[::-1]
    return values[order], vectors[:, order].T


def _snap(direction: np.ndarray, degrees: float = SNAP_DEGREES) -> np.ndarray:
    """The coordinate axis nearest to ``direction`` if within ``degrees``, else itself."""
    k = int(np.argmax(np.abs(direction)))
    if abs(direction[k]) >= np.cos(np.radians(degrees)):
        out = np.zeros(3)
        out[k] = np.sign(direction[k])
        return out
    return direction


def _face_front(direction: np.ndarray) -> np.ndarray:
    """``direction`` or its opposite, whichever points to the front side (+Z, +X, +Y)."""
    d = float(direction @ _FRONT)
    return -direction if d < 0 else direction


def _distance(radius: float) -> float:
    return radius / np.sin(np.radians(0.5 * VIEW_ANGLE))


def _rotate(v: np.ndarray, axis: np.ndarray, degrees: float) -> np.ndarray:
    """Rodrigues rotation of ``v`` about the unit ``axis``."""
    t = np.radians(degrees)
    return v * np.cos(t) + np.cross(axis, v) * np.sin(t) + axis * (axis @ v) * (1 - np.cos(t))


def look_from(vertices, direction, up) -> Camera:
    """A camera looking at the mesh's bounding-box centre from ``direction`` (pointing from
    the centre to the camera), far enough to see the bounding sphere, with ``up`` made
    orthogonal to the direction."""
    centre, radius = _bounds(vertices)
    d = _unit(direction)
    u = np.asarray(up, dtype=np.float64)
    u = u - (u @ d) * d
    u = _unit(u)
    position = centre + _distance(radius) * d
    return Camera(tuple(position), tuple(centre), tuple(u))


def silhouette_area(vertices, directions, cell: float) -> np.ndarray:
    """(d,) area of the silhouette seen along each unit direction (d, 3), estimated by
    the square cells of side ``cell`` that the projected vertices fall into (take about
    3 mean edge lengths: with less, surfaces seen face-on leave empty cells)."""
    v = np.asarray(vertices, dtype=np.float64)
    if len(v) > 200000:  # a regular subset of a very fine mesh covers the same cells
        v = v[:: int(np.ceil(len(v) / 200000))]
    v = v - v.mean(axis=0)
    out = np.zeros(len(directions))
    for i, d in enumerate(np.asarray(directions, dtype=np.float64)):
        d = _unit(d)
        k = int(np.argmin(np.abs(d)))
        a = np.zeros(3)
        a[k] = 1.0
        a = _unit(a - (a @ d) * d)
        b = np.cross(d, a)
        ij = np.floor(np.column_stack([v @ a, v @ b]) / cell).astype(np.int64)
        ij -= ij.min(axis=0)
        key = ij[:, 0] * (int(ij[:, 1].max()) + 1) + ij[:, 1]
        out[i] = np.unique(key).size * cell * cell
    return out


def _largest_silhouette(vertices, faces, up_vec: np.ndarray) -> np.ndarray:
    """The viewing axis (unit, sign not chosen) showing the largest projected area."""
    if faces is None or len(faces) == 0:
        _, axes = principal_axes(vertices)
        return _snap(axes[2])
    k = int(np.argmax(np.abs(up_vec)))
    a = np.zeros(3)
    a[(k + 1) % 3] = 1.0
    a = _unit(a - (a @ up_vec) * up_vec)
    b = np.cross(up_vec, a)
    angles = np.radians(np.arange(0.0, 180.0, 5.0))
    horizontal = np.outer(np.cos(angles), a) + np.outer(np.sin(angles), b)
    axes = [np.array(d) for d in AXES.values() if abs(np.dot(d, up_vec)) < 1e-9]
    candidates = np.vstack([horizontal, *axes, up_vec]) if axes else np.vstack([horizontal, up_vec])
    v, f = np.asarray(vertices, dtype=np.float64), np.asarray(faces)
    edge = np.linalg.norm(v[f[:, 1]] - v[f[:, 0]], axis=1).mean()
    area = silhouette_area(v, candidates, 3.0 * edge)
    best_h = int(np.argmax(area[: len(horizontal)]))
    best = horizontal[best_h]
    best_area = area[best_h]
    for i, axis in enumerate(axes):
        if area[len(horizontal) + i] >= AXIS_PREFERENCE * best_area:
            best, best_area = axis, area[len(horizontal) + i]
            break
    if area[-1] > TOP_VIEW_RATIO * best_area:
        return up_vec.copy()
    return best


def canonical_view(
    vertices, faces=None, up=None, azimuth: float = 20.0, elevation: float = 15.0
) -> Camera:
    """The canonical first view of a mesh (see the module docstring).  ``up``: an axis
    name ("+y", "z", ...) or a vector; ``azimuth``/``elevation`` in degrees turn the
    camera about the up axis and toward it from the straight front view."""
    up_vec = _up_vector(up)
    view = _largest_silhouette(vertices, faces, up_vec)
    if abs(view @ up_vec) > np.cos(np.radians(30.0)):
        # flat across the up axis: from above, the longest axis left to right
        view = up_vec.copy()
        _, axes = principal_axes(vertices, faces)
        middle = _snap(axes[1])
        screen_up = middle - (middle @ view) * view
        if np.linalg.norm(screen_up) < 1e-6:
            screen_up = _snap(axes[2]) - (_snap(axes[2]) @ view) * view
        screen_up = -_face_front(_unit(screen_up))  # the front side at the bottom
    else:
        view = _face_front(view)
        screen_up = _unit(up_vec - (up_vec @ view) * view)
    # turn toward the front (+Z, then +X): of the two turns pick the one facing it more
    turns = [_rotate(view, screen_up, a) for a in (azimuth, -azimuth)]
    direction = max(turns, key=lambda d: float(d @ _TURN_TOWARD))
    right = _unit(np.cross(screen_up, direction))
    direction = _rotate(direction, right, -elevation)
    return look_from(vertices, direction, screen_up)


def preset_view(vertices, name: str, up=None) -> Camera:
    """The view from one side: "+x" puts the camera on the +X side looking toward -X, and
    so on; "isometric" looks from the (+1, +1, +1) corner of the up-axis frame.  The
    screen's up is the up axis, or for views along it the next axis (Z after Y, X after
    Z, Y after X), negated for the view from the positive side (a top view with +Y up has
    -Z at the top of the screen, so +Z is toward the viewer)."""
    up_vec = _up_vector(up)
    key = name.lower()
    if key == "isometric":
        k = int(np.argmax(np.abs(up_vec)))
        a, b = (k + 1) % 3, (k + 2) % 3
        direction = np.zeros(3)
        direction[[a, b]] = 1.0
        direction += up_vec
        return look_from(vertices, direction, up_vec)
    if key not in AXES:
        raise ValueError(f"unknown camera preset {name!r}; use one of {', '.join(PRESETS)}")
    direction = np.array(AXES[key])
    if abs(direction @ up_vec) > 0.99:
        k = int(np.argmax(np.abs(up_vec)))
        nxt = np.zeros(3)
        nxt[(k + 1) % 3] = 1.0
        screen_up = -nxt if direction @ up_vec > 0 else nxt
    else:
        screen_up = up_vec
    return look_from(vertices, direction, screen_up)


def canonical_camera(mesh, up=None) -> dict:
    """:func:`canonical_view` of a :class:`~modalviewer.core.mesh.Mesh` as a dict
    (position, focal_point, view_up)."""
    return canonical_view(mesh.vertices, mesh.faces, up=up).as_dict()


def preset_camera(mesh, name: str, up=None) -> dict:
    """:func:`preset_view` ("+x" ... "-z", "isometric"; "canonical" too) as a dict."""
    if name == "canonical":
        return canonical_camera(mesh, up)
    return preset_view(mesh.vertices, name, up=up).as_dict()
