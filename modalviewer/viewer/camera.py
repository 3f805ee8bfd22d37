"""Cameras for a mesh, as plain numbers (no Qt, no VTK): the canonical first view and the
axis presets.

Canonical view: up is the caller's axis or +Y (most OBJ/PLY/OFF models).  The viewer
looks along the horizontal direction (every 5 degrees) with the largest silhouette,
preferring a coordinate axis within ``AXIS_PREFERENCE`` of the best, or from above when
that shows ``TOP_VIEW_RATIO`` times more (a plate); then it turns by a small azimuth and
elevation to show depth, from the side most models face (+Z for +Y up, -Y for +Z up).
A CAD-like part (mostly coplanar neighbours, sharp feature edges) is turned instead to
the view that shows its sharp edges best.  Without faces the axis of least spread
stands in.
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
DEFAULT_TURN = (20.0, 15.0)  # azimuth, elevation of the canonical view (degrees)
CAD_TURNS = ((20.0, 15.0), (45.0, 15.0), (20.0, 35.0), (45.0, 35.0), (60.0, 30.0))
COPLANAR_SHARE = 0.5  # share of a CAD-like part's edges between coplanar faces
SHARP_SHARE = 0.01  # share of a CAD-like part's edge length on sharp edges
SHARP_DEGREES = 45.0  # the angle between the normals of a sharp edge's faces


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

    @classmethod
    def from_dict(cls, d: dict) -> Camera:
        """The camera of :meth:`as_dict`'s plain data (a window's, a session's)."""
        return cls(tuple(d["position"]), tuple(d["focal_point"]), tuple(d["view_up"]))

    def as_dict(self) -> dict:
        return {
            "position": list(self.position),
            "focal_point": list(self.focal_point),
            "view_up": list(self.up),
        }


@dataclass(frozen=True)
class CameraLink:
    """The similarity ``x_B = focal_b + scale * rotation @ (x_A - focal_a)`` carrying view
    A's camera to view B's: two views that turn, zoom and pan together."""

    rotation: np.ndarray
    scale: float
    focal_a: np.ndarray
    focal_b: np.ndarray

    @classmethod
    def between(cls, a: Camera, b: Camera) -> CameraLink:
        """The link that carries ``a`` to ``b`` as they are (their relative viewpoint)."""
        (fa, da), (fb, db) = _frame(a), _frame(b)
        return cls(fb @ fa.T, db / da, np.asarray(a.focal_point), np.asarray(b.focal_point))

    @classmethod
    def facing(cls, a, b) -> CameraLink:
        """The link showing mesh ``b`` as mesh ``a`` is seen, about its own centre and size."""
        centre_a, centre_b = ((m.vertices.min(0) + m.vertices.max(0)) / 2 for m in (a, b))
        scale = b.bounding_box_diagonal / (a.bounding_box_diagonal or 1.0)
        return cls(np.eye(3), scale, centre_a, centre_b)

    def carry(self, camera: Camera, from_a: bool = True) -> tuple[Camera, float]:
        """``camera`` carried A to B (or B to A), and the factor its parallel scale takes."""
        rot, s, src, dst = self.rotation, self.scale, self.focal_a, self.focal_b
        if not from_a:
            rot, s, src, dst = rot.T, 1.0 / s, dst, src

        def to_dst(x):
            return tuple(dst + s * rot @ (np.asarray(x) - src))

        up = tuple(rot @ np.asarray(camera.up))
        return Camera(to_dst(camera.position), to_dst(camera.focal_point), up), s


def _frame(camera: Camera) -> tuple[np.ndarray, float]:
    """((3, 3) columns right, up, back of ``camera``; its distance to the focal point)."""
    d = np.subtract(camera.focal_point, camera.position)
    distance = float(np.linalg.norm(d)) or 1.0
    back = -d / distance
    up = np.asarray(camera.up, dtype=float)
    up = up - back * float(up @ back)
    up /= np.linalg.norm(up) or 1.0
    return np.column_stack([np.cross(up, back), up, back]), distance


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    n = np.linalg.norm(v)
    if n == 0:
        raise ValueError("zero vector")
    return v / n


def _up_vector(up) -> np.ndarray:
    up = DEFAULT_UP if up is None else up
    if isinstance(up, str):
        key = up.lower() if up[0] in "+-" else "+" + up.lower()
        if key not in AXES:
            raise ValueError(f"unknown up axis {up!r}; use one of {', '.join(AXES)}")
        return np.array(AXES[key])
    return _unit(up)


def principal_axes(vertices, faces=None) -> tuple[np.ndarray, np.ndarray]:
    """(variances (3,) descending, axes as rows (3, 3)): the area-weighted second moments
    of the triangles, or of the vertices without faces."""
    v = np.asarray(vertices, dtype=np.float64)
    if faces is None or len(faces) == 0:
        c = v - v.mean(axis=0)
        cov = c.T @ c / max(len(v), 1)
    else:
        f = np.asarray(faces)
        x0, x1, x2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        area = 0.5 * np.linalg.norm(np.cross(x1 - x0, x2 - x0), axis=1)
        w = area / (float(area.sum()) or 1.0)
        centroid = (x0 + x1 + x2) / 3.0
        mean = w @ centroid
        # exact second moment of a uniform triangle: (sum_i x_i x_i^T + s s^T) / 12 with
        # s = x0 + x1 + x2, taken about the surface's mean
        a, b, c = x0 - mean, x1 - mean, x2 - mean
        cov = sum(np.einsum("i,ij,ik->jk", w, x, x) for x in (a, b, c, a + b + c)) / 12.0
    values, vectors = np.linalg.eigh(cov)
    order = np.argsort(values)[::-1]
    return values[order], vectors[:, order].T


def _snap(direction: np.ndarray, degrees: float = SNAP_DEGREES) -> np.ndarray:
    """The coordinate axis nearest to ``direction`` if within ``degrees``, else itself."""
    k = int(np.argmax(np.abs(direction)))
    if abs(direction[k]) >= np.cos(np.radians(degrees)):
        return np.sign(direction[k]) * np.eye(3)[k]
    return direction


def _for_up(v: np.ndarray, up: np.ndarray) -> np.ndarray:
    """``v``, a direction for +Y up, turned as +Y is turned to ``up``: +Z to -Y for +Z up,
    where a quarter turn about X puts a Y-up model's front (and Z-up tools put theirs)."""
    turn = np.cross([0.0, 1.0, 0.0], up) if abs(up[1]) < 1.0 - 1e-9 else np.eye(3)[0]
    return _rotate(v, _unit(turn), np.degrees(np.arccos(np.clip(up[1], -1.0, 1.0))))


def _face_front(direction: np.ndarray, front: np.ndarray) -> np.ndarray:
    """``direction`` or its opposite, whichever points to the ``front`` side."""
    return -direction if float(direction @ front) < 0 else direction


def _rotate(v: np.ndarray, axis: np.ndarray, degrees: float) -> np.ndarray:
    """Rodrigues rotation of ``v`` about the unit ``axis``."""
    t = np.radians(degrees)
    return v * np.cos(t) + np.cross(axis, v) * np.sin(t) + axis * (axis @ v) * (1 - np.cos(t))


def look_from(vertices, direction, up) -> Camera:
    """A camera at ``direction`` from the bounding-box centre, seeing the bounding sphere."""
    v = np.asarray(vertices, dtype=np.float64)
    lo, hi = v.min(axis=0), v.max(axis=0)
    centre, radius = 0.5 * (lo + hi), max(0.5 * float(np.linalg.norm(hi - lo)), 1e-12)
    d = _unit(direction)
    u = np.asarray(up, dtype=np.float64)
    u = _unit(u - (u @ d) * d)
    position = centre + radius / np.sin(np.radians(0.5 * VIEW_ANGLE)) * d
    return Camera(tuple(position), tuple(centre), tuple(u))


def silhouette_area(points, cell: float, directions) -> np.ndarray:
    """(d,) silhouette area of ``points`` along each direction (d, 3): the square cells of
    side ``cell`` the projected points fall into."""
    v = np.asarray(points, dtype=np.float64)
    v = v - v.mean(axis=0)
    out = np.zeros(len(directions))
    for i, d in enumerate(np.asarray(directions, dtype=np.float64)):
        d = _unit(d)
        a = np.eye(3)[int(np.argmin(np.abs(d)))]
        a = _unit(a - (a @ d) * d)
        b = np.cross(d, a)
        ij = np.floor(np.column_stack([v @ a, v @ b]) / cell).astype(np.int64)
        ij -= ij.min(axis=0)
        key = ij[:, 0] * (int(ij[:, 1].max()) + 1) + ij[:, 1]
        out[i] = np.unique(key).size * cell * cell
    return out


def _surface_points(vertices, faces, samples: int = 40000) -> tuple[np.ndarray, float]:
    """(points, cell): uniform points on the surface (a fixed seed: a mesh always gets the
    same view) and a cell side a surface seen face-on leaves no cell of empty."""
    v, f = np.asarray(vertices, dtype=np.float64), np.asarray(faces)
    x0, x1, x2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(x1 - x0, x2 - x0), axis=1)
    total = float(area.sum())
    rng = np.random.default_rng(0)
    face = rng.choice(len(f), samples, p=area / total)
    r1, r2 = np.sqrt(rng.random(samples)), rng.random(samples)
    points = (
        (1 - r1)[:, None] * x0[face]
        + (r1 * (1 - r2))[:, None] * x1[face]
        + (r1 * r2)[:, None] * x2[face]
    )
    return points, 2.0 * np.sqrt(total / samples)


def _largest_silhouette(vertices, faces, up_vec: np.ndarray) -> np.ndarray:
    """The viewing axis (unit, sign not chosen) showing the largest projected area."""
    if faces is None or len(faces) == 0:
        _, axes = principal_axes(vertices)
        return _snap(axes[2])
    a = np.eye(3)[(int(np.argmax(np.abs(up_vec))) + 1) % 3]
    a = _unit(a - (a @ up_vec) * up_vec)
    b = np.cross(up_vec, a)
    angles = np.radians(np.arange(0.0, 180.0, 5.0))
    horizontal = np.outer(np.cos(angles), a) + np.outer(np.sin(angles), b)
    axes = [np.array(d) for d in AXES.values() if abs(np.dot(d, up_vec)) < 1e-9]
    candidates = np.vstack([horizontal, *axes, up_vec])
    area = silhouette_area(*_surface_points(vertices, faces), candidates)
    best_h = int(np.argmax(area[: len(horizontal)]))
    best, best_area = horizontal[best_h], area[best_h]
    for i, axis in enumerate(axes):
        if area[len(horizontal) + i] >= AXIS_PREFERENCE * best_area:
            best, best_area = axis, area[len(horizontal) + i]
            break
    if area[-1] > TOP_VIEW_RATIO * best_area:
        return up_vec.copy()
    return best


def sharp_edges(vertices, faces) -> tuple[np.ndarray, np.ndarray] | None:
    """((s, 3) edge vectors, (s, 2, 3) their faces' unit normals) of the sharp edges of a
    CAD-like surface; None for other surfaces."""
    v, f = np.asarray(vertices, dtype=np.float64), np.asarray(faces)
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normals /= np.maximum(np.linalg.norm(normals, axis=1), 1e-300)[:, None]
    edges = np.sort(np.stack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]], 1).reshape(-1, 2), 1)
    key = edges[:, 0].astype(np.int64) * len(v) + edges[:, 1]
    order = np.argsort(key)
    edges, face, key = edges[order], order // 3, key[order]
    i = np.flatnonzero(key[1:] == key[:-1])  # edges with two faces
    if i.size == 0:
        return None
    pair = np.stack([normals[face[i]], normals[face[i + 1]]], axis=1)
    cos = np.einsum("ij,ij->i", pair[:, 0], pair[:, 1])
    vectors = v[edges[i, 1]] - v[edges[i, 0]]
    length = np.linalg.norm(vectors, axis=1)
    sharp = cos < np.cos(np.radians(SHARP_DEGREES))
    coplanar = np.mean(cos > np.cos(np.radians(0.5)))
    if coplanar < COPLANAR_SHARE or length[sharp].sum() < SHARP_SHARE * length.sum():
        return None
    return vectors[sharp], pair[sharp]


def canonical_view(
    vertices, faces=None, up=None, azimuth: float | None = None, elevation: float | None = None
) -> Camera:
    """The canonical first view (module docstring); ``up`` an axis name or a vector;
    ``azimuth``/``elevation`` (degrees) turn from the front view (default
    :data:`DEFAULT_TURN`, for a CAD-like part the best of :data:`CAD_TURNS`)."""
    up_vec = _up_vector(up)
    front, toward = (_for_up(v, up_vec) for v in (_FRONT, _TURN_TOWARD))
    view = _largest_silhouette(vertices, faces, up_vec)
    if abs(view @ up_vec) > np.cos(np.radians(30.0)):
        # flat across the up axis: from above, the longest axis left to right
        view = up_vec.copy()
        _, axes = principal_axes(vertices, faces)
        middle = _snap(axes[1])
        screen_up = middle - (middle @ view) * view
        if np.linalg.norm(screen_up) < 1e-6:
            screen_up = _snap(axes[2]) - (_snap(axes[2]) @ view) * view
        screen_up = -_face_front(_unit(screen_up), front)  # the front side at the bottom
    else:
        view = _face_front(view, front)
        screen_up = _unit(up_vec - (up_vec @ view) * view)
    edges = None
    if azimuth is None and elevation is None and faces is not None and len(faces):
        edges = sharp_edges(vertices, faces)
    if edges is None:
        az = DEFAULT_TURN[0] if azimuth is None else azimuth
        el = DEFAULT_TURN[1] if elevation is None else elevation
        direction = _turned(view, screen_up, az, el, toward)
    else:
        # the turn showing the creases best: their lengths weighted by the cosine of the
        # less visible face (a crease shows where both faces are seen)
        lengths, normals = np.linalg.norm(edges[0], axis=1), edges[1]
        turns = [_turned(view, screen_up, a, e, toward) for a, e in CAD_TURNS]
        direction = max(turns, key=lambda d: lengths @ np.clip((normals @ d).min(1), 0, None))
    return look_from(vertices, direction, screen_up)


def _turned(view, screen_up, azimuth: float, elevation: float, toward) -> np.ndarray:
    """``view`` turned by ``azimuth`` about ``screen_up`` to the side of ``toward``, then
    by ``elevation`` toward up."""
    turns = [_rotate(view, screen_up, a) for a in (azimuth, -azimuth)]
    direction = max(turns, key=lambda d: float(d @ toward))
    right = _unit(np.cross(screen_up, direction))
    return _rotate(direction, right, -elevation)


def preset_view(vertices, name: str, up=None) -> Camera:
    """The view from one side ("+x": the camera on the +X side), or "isometric" from the
    (+1, +1, +1) corner of the up-axis frame.  Screen up is the up axis; along it the
    next axis (Z after Y), negated from the positive side (a top view with +Y up has +Z
    toward the viewer)."""
    up_vec = _up_vector(up)
    key = name.lower()
    k = int(np.argmax(np.abs(up_vec)))
    if key == "isometric":  # +1 along the two other axes, and up
        return look_from(vertices, 1.0 - np.eye(3)[k] + up_vec, up_vec)
    if key not in AXES:
        raise ValueError(f"unknown camera preset {name!r}; use one of {', '.join(PRESETS)}")
    direction = np.array(AXES[key])
    if abs(direction @ up_vec) > 0.99:
        nxt = np.eye(3)[(k + 1) % 3]
        screen_up = -nxt if direction @ up_vec > 0 else nxt
    else:
        screen_up = up_vec
    return look_from(vertices, direction, screen_up)


UP_CHOICES = ("auto", *AXES)
"""What an up axis can be set to: "auto" (:func:`detect_up`) or an axis."""
FLAT_ASPECT = 0.35  # a shape thinner than this along z (a plate) gets no +Z claim
SUPPORT_SLICE = 0.04  # the bottom slice of the extent the supports (legs) are found in
BASE_SLICE = 0.01  # the bottom slice a flat base lies in
BASE_SHARE = 0.02  # share of the area a flat base must hold
BASE_NORMAL = 0.985  # |n . axis| of a face lying flat
BASE_SPAN = 0.5  # share of the horizontal extents a base must span
# a figure on two feet along z stands Z-up when it is at least this many times taller
# (z) than deep (y): a scanned person or character, whose front or back, lying along y,
# may touch the bottom slice in several places (hands, nose); a table on two of its legs
# along z is not that deep
BIPED_ASPECT = 2.0


def _supports(v: np.ndarray, f: np.ndarray, axis: int) -> int:
    """The connected pieces in the bottom ``SUPPORT_SLICE`` along ``axis``: its feet."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    x = v[:, axis]
    low = x <= x.min() + SUPPORT_SLICE * max(float(np.ptp(x)), 1e-300)
    index = np.full(len(v), -1)
    index[low] = np.arange(int(low.sum()))
    edges = np.vstack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    edges = edges[low[edges[:, 0]] & low[edges[:, 1]]]
    n = int(low.sum())
    graph = sp.coo_matrix((np.ones(len(edges)), (index[edges[:, 0]], index[edges[:, 1]])), (n, n))
    return int(connected_components(graph, directed=False)[0])


def _flat_base(v: np.ndarray, f: np.ndarray, axis: int) -> float:
    """The share of the area lying flat in the bottom ``BASE_SLICE`` along ``axis`` (a
    base); 0 unless it spans ``BASE_SPAN`` of the other two extents."""
    x0, x1, x2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(x1 - x0, x2 - x0)
    area = np.linalg.norm(n, axis=1)
    total = float(area.sum()) or 1.0
    x = v[:, axis]
    low = x <= x.min() + BASE_SLICE * max(float(np.ptp(x)), 1e-300)
    flat = np.abs(n[:, axis]) >= BASE_NORMAL * np.maximum(area, 1e-300)
    base = flat & low[f].all(axis=1)
    if not base.any():
        return 0.0
    others = [a for a in range(3) if a != axis]
    span = np.ptp(v[f[base].ravel()][:, others], axis=0)
    if np.any(span < BASE_SPAN * np.ptp(v[:, others], axis=0)):
        return 0.0
    return float(area[base].sum() / total)


def detect_up(vertices, faces=None) -> str | None:
    """ "+z" when the mesh clearly stands on the XY plane, else None (+Y applies).  No
    claim for a plate (thinner than ``FLAT_ASPECT`` along z) or three feet along y; +Z
    for two feet along z under a figure ``BIPED_ASPECT`` times taller than deep, three
    feet along z, or (a closed surface) a flat base along z holding
    ``BASE_SHARE`` of the area with a base along y under a quarter of that."""
    if faces is None or len(faces) == 0:
        return None
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    extent = np.ptp(v, axis=0)
    if extent[2] < FLAT_ASPECT * float(extent.max()):
        return None
    legs_z, legs_y = _supports(v, f, 2), _supports(v, f, 1)
    if legs_z == 2 and extent[2] >= BIPED_ASPECT * extent[1]:
        return "+z"  # a figure standing on two feet
    if legs_y >= 3:  # it stands on feet along y: Y-up
        return None
    if legs_z >= 3:
        return "+z"
    edges = np.sort(np.vstack([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    if (np.unique(edges, axis=0, return_counts=True)[1] == 1).any():
        return None  # an open sheet lying flat in part (a folded plate) has no base
    base_z, base_y = _flat_base(v, f, 2), _flat_base(v, f, 1)
    if base_z >= BASE_SHARE and base_y < 0.25 * base_z:
        return "+z"
    return None


def up_axis_of(vertices, faces=None, chosen: str | None = None) -> str:
    """The up axis in effect: ``chosen`` (an axis name) unless it is None or "auto",
    then :func:`detect_up`'s claim, or :data:`DEFAULT_UP`."""
    if chosen not in (None, "auto"):
        return chosen
    return detect_up(vertices, faces) or DEFAULT_UP


def orbit_view(vertices, azimuth: float, elevation: float, up=None) -> Camera:
    """The camera at ``azimuth`` degrees about the up axis and ``elevation`` toward it,
    from the front: the axis after the up axis (+Z for +Y up).  Azimuth 90: the right."""
    up_vec = _up_vector(up)
    k = int(np.argmax(np.abs(up_vec)))
    front = np.sign(up_vec[k]) * np.eye(3)[(k + 1) % 3]
    right = np.cross(up_vec, front)
    a, e = np.radians(float(azimuth)), np.radians(float(elevation))
    if abs(abs(float(elevation)) - 90.0) < 1e-9:
        return preset_view(vertices, "+" + "xyz"[k] if e * up_vec[k] > 0 else "-" + "xyz"[k], up)
    direction = np.cos(e) * (np.cos(a) * front + np.sin(a) * right) + np.sin(e) * up_vec
    return look_from(vertices, direction, up_vec)


def parse_view(text: str) -> str | tuple[float, float]:
    """A view as the CLI's ``--view`` gives it: "canonical", a preset ("+x" ... "-z",
    "iso" or "isometric"), or "AZ,EL" in degrees; ValueError otherwise."""
    key = str(text).strip().lower()
    if key in ("canonical", "isometric", *AXES):
        return key
    if key == "iso":
        return "isometric"
    try:
        az, el = (float(p) for p in key.split(","))
    except ValueError:  # not two numbers
        az = el = np.nan
    if np.isfinite(az) and np.isfinite(el) and -90.0 <= el <= 90.0:
        return az, el
    raise ValueError(
        f"unknown view {text!r}: use canonical, {', '.join(AXES)}, iso or AZ,EL in degrees "
        "(elevation -90 .. 90)"
    )


def view_camera(vertices, faces, view, up=None) -> Camera:
    """The camera of a :func:`parse_view` result (or its text) with up axis ``up``."""
    view = parse_view(view) if isinstance(view, str) else view
    if view == "canonical":
        return canonical_view(vertices, faces, up=up)
    if isinstance(view, str):
        return preset_view(vertices, view, up=up)
    return orbit_view(vertices, view[0], view[1], up=up)


def canonical_camera(mesh, up=None) -> dict:
    """:func:`canonical_view` of ``mesh`` as :meth:`Camera.as_dict`."""
    return canonical_view(mesh.vertices, mesh.faces, up=up).as_dict()
