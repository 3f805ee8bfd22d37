"""Degenerate triangles: the loader's zero-area repair and ``fix_slivers``, timed.

    python -m benchmarks.slivers [--grid 200] [--meshes assets/spot.obj ...]

Cases (needles and caps from :func:`add_slivers`, which the tests of the repairs use too):

- loader: an icosphere of 40962 vertices with 13000 zero-area caps at mid-edge (flipped)
  and at 2 % of an edge (collapsed), against the same mesh without them;
- fix_slivers on an icosphere(3) with 20 needles and 20 caps of quality 1e-8, whose
  shells Hessian cannot be factorised, then the shells spectrum (16 modes) against the
  clean sphere's;
- fix_slivers on each ``--meshes`` file with 1 % needles and 1 % caps (eps 1e-6);
- fix_slivers on a marching-cubes surface of a bumpy sphere on a ``--grid``^3 grid
  (pyvista; 143k vertices for 200), as it is and with 1500 needles and 1500 caps (two
  seeds: one that MeshLab's T-vertex removal repairs, one that needs the remeshing).

Results go to ``benchmarks/results/slivers.json``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import modalviewer as mv  # noqa: E402
from benchmarks.run import save_result  # noqa: E402
from modalviewer.core.mesh import Mesh  # noqa: E402
from modalviewer.core.primitives import icosphere  # noqa: E402


def add_slivers(
    mesh: Mesh, needles: int, caps: int, eps: float, seed: int = 0, at: float = 0.5
) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of ``mesh`` with nearly degenerate triangles, as remeshers and
    iso-surfaces make them, for tests of the repairs: ``caps`` random faces (a, b, c)
    split at x = (1 - at) a + at b moved ``eps`` (relative) towards c, ``needles`` edges
    split at ``eps`` of their length from one end.  A closed mesh stays closed; the raw
    arrays hold faces of zero area for eps = 0, which ``repair_mesh`` repairs."""
    rng = np.random.default_rng(seed)
    v = [np.asarray(p) for p in mesh.vertices]
    f = np.array(mesh.faces)
    picks = iter(rng.permutation(len(f)))
    for _ in range(caps):
        t = next(picks)
        a, b, c = f[t]
        x = len(v)
        v.append(((1 - at) * v[a] + at * v[b]) * (1 - eps) + eps * v[c])
        f[t] = [a, b, x]  # the cap
        f = np.vstack([f, [[b, c, x], [c, a, x]]])
    made = 0
    while made < needles:
        t = next(picks)
        a, b, c = f[t]
        other = np.flatnonzero(((f == b) & (np.roll(f, -1, axis=1) == a)).any(axis=1))
        if len(other) != 1 or len(set(f[t]) & set(f[other[0]])) != 2:
            continue  # on the boundary, or not a simple neighbour
        o = other[0]
        d = next(int(x) for x in f[o] if x not in (a, b))  # the face across runs (b, a, d)
        x = len(v)
        v.append(v[a] * (1 - eps) + eps * v[b])
        f[t] = [a, x, c]
        f[o] = [b, x, d]
        f = np.vstack([f, [[x, b, c], [x, a, d]]])
        made += 1
    return np.array(v), f


def marching_cubes_surface(n: int) -> mv.Mesh:
    import pyvista as pv

    x = np.linspace(-1.2, 1.2, n)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    field = np.sqrt(X**2 + Y**2 + Z**2) + 0.15 * np.sin(5 * X) * np.sin(4 * Y)
    grid = pv.ImageData(dimensions=(n, n, n), spacing=(x[1] - x[0],) * 3, origin=(-1.2,) * 3)
    grid.point_data["f"] = field.ravel(order="F")
    s = grid.contour([1.0], method="marching_cubes").triangulate().clean()
    faces = np.asarray(s.faces).reshape(-1, 4)[:, 1:]
    return mv.repair_mesh(np.asarray(s.points, dtype=float), faces, source=f"mc{n}")


def fix_row(name: str, mesh: mv.Mesh) -> dict:
    t0 = time.perf_counter()
    fixed = mv.fix_slivers(mesh)
    seconds = time.perf_counter() - t0
    r = fixed.report
    row = {
        "mesh": name,
        "vertices": mesh.n_vertices,
        "method": r.method,
        "triangles_changed": r.triangles_changed,
        "triangles_before": r.triangles_before,
        "below_0.05": [r.below_min_quality_before, r.below_min_quality_after],
        "below_1e-3": [r.slivers_before, r.slivers_after],
        "worst_quality": [r.worst_quality_before, r.worst_quality_after],
        "max_vertex_shift": r.max_vertex_shift,
        "max_deviation": r.max_deviation,
        "topology": [mesh.n_boundary_edges, fixed.n_boundary_edges, mesh.n_components],
        "seconds": round(seconds, 3),
    }
    print(
        f"{name}: {r.triangles_changed} of {r.triangles_before} triangles changed, "
        f"below 0.05 {r.below_min_quality_before} -> {r.below_min_quality_after}, worst "
        f"{r.worst_quality_before:.2g} -> {r.worst_quality_after:.2g}, shift "
        f"{r.max_vertex_shift:.1e}, deviation {r.max_deviation:.1e}, {seconds:.2f} s "
        f"({r.method.split(' (')[0]})",
        flush=True,
    )
    return row, fixed


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grid", type=int, default=200, help="marching-cubes grid size")
    ap.add_argument("--meshes", nargs="*", default=[str(ROOT / "assets" / "spot.obj")])
    args = ap.parse_args(argv)
    out: dict = {"loader": [], "fix_slivers": []}

    sphere = icosphere(6)
    t0 = time.perf_counter()
    mv.repair_mesh(sphere.vertices, sphere.faces)
    clean = time.perf_counter() - t0
    for at in (0.5, 0.02):
        v, f = add_slivers(sphere, needles=0, caps=13000, eps=0.0, at=at)
        t0 = time.perf_counter()
        mesh = mv.repair_mesh(v, f, source=f"caps at {at}")
        seconds = time.perf_counter() - t0
        print(f"loader, 13000 zero-area caps at {at}: {seconds:.2f} s (clean {clean:.2f} s)")
        print("  " + str(mesh.report))
        out["loader"].append(
            {
                "caps_at": at,
                "seconds": round(seconds, 3),
                "seconds_clean": round(clean, 3),
                "boundary_edges": mesh.n_boundary_edges,
                "report": str(mesh.report),
            }
        )

    small = icosphere(3)
    v, f = add_slivers(small, needles=20, caps=20, eps=1e-8, seed=2)
    bad = mv.Mesh(v, f)
    try:
        mv.compute_spectrum(bad, "shells", k=16)
        before = "computed"
    except mv.EigenError as exc:
        before = str(exc)
    row, fixed = fix_row("icosphere(3) + 20 needles + 20 caps", bad)
    t0 = time.perf_counter()
    spec = mv.compute_spectrum(fixed, "shells", k=16)
    row["shells_seconds_after"] = round(time.perf_counter() - t0, 3)
    ref = mv.compute_spectrum(small, "shells", k=16)
    row["shells_before"] = before
    row["eigenvalue_rel_diff_to_clean"] = float(
        np.max(np.abs(spec.eigenvalues[6:] / ref.eigenvalues[6:] - 1))
    )
    print(f"  shells before: {before[:100]}...; after: {row['eigenvalue_rel_diff_to_clean']:.3f}")
    out["fix_slivers"].append(row)

    for path in args.meshes:
        mesh = mv.load_mesh(path)
        k = mesh.n_faces // 100
        v, f = add_slivers(mesh, needles=k, caps=k, eps=1e-6, seed=1)
        out["fix_slivers"].append(
            fix_row(f"{Path(path).name} + 1 % needles and caps", mv.repair_mesh(v, f))[0]
        )

    mc = marching_cubes_surface(args.grid)
    out["fix_slivers"].append(fix_row(f"marching cubes {args.grid}^3", mc)[0])
    # seed 6: MeshLab's flips and collapses keep the topology; seed 3: its collapses would
    # make edges non-manifold (3 of the first 8 seeds do), so the local remeshing runs
    for seed in (6, 3):
        v, f = add_slivers(mc, needles=1500, caps=1500, eps=1e-6, seed=seed)
        name = f"marching cubes {args.grid}^3 + 1500 needles + 1500 caps (seed {seed})"
        out["fix_slivers"].append(fix_row(name, mv.repair_mesh(v, f))[0])
    save_result("slivers", out)


if __name__ == "__main__":
    main()
