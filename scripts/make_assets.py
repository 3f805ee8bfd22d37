"""Write the demo meshes to assets/ (reproducible: run ``python scripts/make_assets.py``).

The plates, the double torus and the machined part (unions of voxels) are made here and
the bumpy plate by ``modalviewer.core.demo_shapes``; the two hands are iso-surfaces of a
smooth union of capsules (VTK flying edges), one with the middle finger bent by 80
degrees at its middle joint (lengths kept, so the bend is nearly isometric away from
the joint).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from modalviewer.core import demo_shapes  # noqa: E402
from modalviewer.core.cleaning import repair_mesh  # noqa: E402
from modalviewer.core.mesh import Mesh  # noqa: E402
from modalviewer.core.primitives import grid_plate  # noqa: E402

ASSETS = ROOT / "assets"

PLATE_N = (48, 24)  # grid cells of the Fig. 1 plate, 2 x 1
FOLD_X = 1.0  # the fold runs along the grid line x = 1


def plate() -> Mesh:
    """Flat 2 x 1 plate, 49 x 25 vertices."""
    return grid_plate(PLATE_N[0], PLATE_N[1], width=2.0, height=1.0)


def folded_plate(angle_degrees: float = 90.0) -> Mesh:
    """:func:`plate` folded isometrically along the mesh line x = 1 (edge lengths kept)."""
    base = plate()
    v = np.array(base.vertices)
    right = v[:, 0] > FOLD_X + 1e-12
    a = np.radians(angle_degrees)
    d = v[right, 0] - FOLD_X
    v[right, 0] = FOLD_X + d * np.cos(a)
    v[right, 2] = d * np.sin(a)
    return Mesh(v, base.faces)


def voxel_surface(solid: np.ndarray, size: float = 1.0) -> Mesh:
    """Outward-oriented boundary of a union of cubes ``solid[i, j, k]`` (edge ``size``),
    two triangles per square, coinciding corners merged.  The solid must not touch
    itself along an edge only (non-manifold)."""
    solid = np.pad(np.asarray(solid, dtype=bool), 1)
    quads = []
    # for each axis and direction, faces where solid meets empty
    corners = {
        0: np.array([[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]]),
        1: np.array([[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]),
        2: np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
    }
    for axis in range(3):
        for direction in (1, -1):
            neighbour = np.roll(solid, -direction, axis=axis)
            cells = np.argwhere(solid & ~neighbour)
            quad = corners[axis] + (direction == 1) * np.eye(3, dtype=int)[axis]
            if direction == -1:
                quad = quad[::-1]  # reversed winding: normal along -axis
            quads.append(cells[:, None, :] + quad[None, :, :])
    q = np.concatenate(quads).reshape(-1, 3).astype(np.float64) - 1.0  # undo the padding
    idx = np.arange(len(q)).reshape(-1, 4)
    faces = np.concatenate([idx[:, [0, 1, 2]], idx[:, [0, 2, 3]]])
    mesh = repair_mesh(q * size, faces, source="voxels")
    return Mesh(mesh.vertices, mesh.faces)


def double_torus(cells: int = 4) -> Mesh:
    """A 7 x 4 x 1 slab with two square holes, ``cells`` voxels per unit length: genus two,
    flat faces bounded by sharp edges (Fig. 3)."""
    c = cells
    solid = np.ones((7 * c, 4 * c, 1 * c), dtype=bool)
    solid[1 * c : 3 * c, 1 * c : 3 * c, :] = False
    solid[4 * c : 6 * c, 1 * c : 3 * c, :] = False
    return voxel_surface(solid, 1.0 / c)


def machined_part(cells: int = 4) -> Mesh:
    """An L-shaped bracket with a through hole and a raised boss (rocker-arm spirit, Fig. 8)."""
    c = cells
    solid = np.zeros((10 * c, 4 * c, 6 * c), dtype=bool)
    solid[:, :, : 1 * c] = True  # base plate 10 x 4 x 1
    solid[: 1 * c, :, :] = True  # upright wall 1 x 4 x 6
    solid[6 * c : 8 * c, 1 * c : 3 * c, : 1 * c] = False  # through hole in the base
    solid[2 * c : 4 * c, 1 * c : 3 * c, 1 * c : 2 * c] = True  # boss on the base
    return voxel_surface(solid, 1.0 / c)


# finger bases on the palm's top edge (x), lengths, radii; palm spans y in [-1, 0.9]
FINGERS = [(-0.75, 1.3, 0.17), (-0.25, 1.6, 0.18), (0.25, 1.45, 0.18), (0.72, 1.1, 0.16)]
THUMB = ((-1.0, -0.2), (-1.75, 0.55), 0.2)
BENT = 1  # the middle finger


def _capsule(p, a, b, r):
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1) - r


def _smin(a, b, k=0.12):
    h = np.clip(0.5 + 0.5 * (b - a) / k, 0.0, 1.0)
    return b * (1 - h) + a * h - k * h * (1 - h)


def hand_sdf(points: np.ndarray, bent: bool) -> tuple[np.ndarray, dict]:
    """Signed distance-like field of the hand; also returns the fingertip positions."""
    palm_a, palm_b = np.array([0.0, -0.55, 0.0]), np.array([0.0, 0.55, 0.0])
    d = _capsule(points * np.array([1.0 / 2.4, 1.0, 1.0 / 0.55]), palm_a, palm_b, 0.45) * 0.55
    tips = {}
    for i, (x, length, r) in enumerate(FINGERS):
        base = np.array([x, 0.75, 0.0])
        joint = base + np.array([0.0, 0.55 * length, 0.0])
        rest = 0.45 * length
        if bent and i == BENT:
            a = np.radians(80.0)
            tip = joint + rest * np.array([0.0, np.cos(a), -np.sin(a)])
        else:
            tip = joint + np.array([0.0, rest, 0.0])
        finger = np.minimum(
            _capsule(points, base, joint, r), _capsule(points, joint, tip, r * 0.95)
        )
        d = _smin(d, finger)
        tips[f"finger{i}"] = (tip + (tip - joint) / np.linalg.norm(tip - joint) * r * 0.95).tolist()
    (bx, by), (tx, ty), r = THUMB
    thumb_a, thumb_b = np.array([bx, by, 0.0]), np.array([tx, ty, 0.0])
    d = _smin(d, _capsule(points, thumb_a, thumb_b, r))
    tips["thumb"] = (thumb_b + (thumb_b - thumb_a) / np.linalg.norm(thumb_b - thumb_a) * r).tolist()
    return d, tips


def hand(bent: bool, spacing: float = 0.04):
    """Iso-surface of :func:`hand_sdf` (flying edges), Taubin-smoothed to tame slivers."""
    import pyvista as pv

    lo, hi = np.array([-2.2, -1.4, -1.6]), np.array([1.3, 2.8, 0.8])
    dims = np.ceil((hi - lo) / spacing).astype(int) + 1
    grid = pv.ImageData(dimensions=dims, spacing=(spacing,) * 3, origin=lo)
    values, tips = hand_sdf(np.asarray(grid.points), bent)
    grid.point_data["d"] = values
    surface = grid.contour([0.0], scalars="d", method="flying_edges").triangulate().clean()
    surface = surface.connectivity("largest").smooth_taubin(n_iter=30, pass_band=0.1)
    faces = np.asarray(surface.faces).reshape(-1, 4)[:, 1:]
    mesh = repair_mesh(np.asarray(surface.points), faces, source="hand")
    return Mesh(mesh.vertices, mesh.faces), tips


def write_obj(path: Path, mesh: Mesh) -> None:
    with open(path, "w") as fh:
        fh.write("# generated by scripts/make_assets.py (modalviewer)\n")
        np.savetxt(fh, mesh.vertices, fmt="v %.7f %.7f %.7f")
        np.savetxt(fh, mesh.faces + 1, fmt="f %d %d %d")


def main() -> int:
    shapes = {
        "demo_plate": plate(),
        "demo_folded_plate": folded_plate(),
        "demo_bumpy_plate": demo_shapes.bumpy_plate(),
        "demo_double_torus": double_torus(6),
        "demo_machined_part": machined_part(5),
    }
    landmarks = {}
    for name, bent in (("demo_hand", False), ("demo_hand_bent", True)):
        mesh, tips = hand(bent)
        shapes[name] = mesh
        landmarks[name] = {
            key: int(np.argmin(np.linalg.norm(mesh.vertices - np.array(p), axis=1)))
            for key, p in tips.items()
        }
    for name, mesh in shapes.items():
        if not (mesh.is_edge_manifold and mesh.is_consistently_oriented):
            raise SystemExit(f"{name} is not a clean surface")
        write_obj(ASSETS / f"{name}.obj", mesh)
        print(f"{name}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, "
              f"{mesh.n_components} component(s), closed={mesh.n_boundary_edges == 0}")  # fmt: skip
    (ASSETS / "demo_landmarks.json").write_text(json.dumps(landmarks, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
