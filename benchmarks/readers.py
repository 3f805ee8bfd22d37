"""Reading mesh files: modalviewer's strict readers against trimesh's, per format.

    python -m benchmarks.readers [--mesh MESH] [--level 3] [--repeat 3]

The mesh is ``benchmarks.curved.case_mesh(mesh, "loop", level)`` (by default homer,
Loop-subdivided three times: 384,002 vertices, 768,000 triangles), written by trimesh
as OBJ, binary PLY, ASCII PLY, binary STL and OFF to a temporary folder.  Each file is
read ``--repeat`` times in this process by ``modalviewer.readers.read_mesh_file`` and by
``trimesh.load(process=False, maintain_order=True)``; the table gives the best time of
each.  trimesh keeps STL's corners as they are (three vertices per triangle); the
strict reader merges them into the distinct positions, as a vertex number needs.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

FORMATS = {
    "OBJ": ("mesh.obj", {}),
    "PLY binary": ("mesh.ply", {}),
    "PLY ASCII": ("mesh_ascii.ply", {"encoding": "ascii"}),
    "STL binary": ("mesh.stl", {}),
    "OFF": ("mesh.off", {}),
}


def best_seconds(read, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        read()
        best = min(best, time.perf_counter() - start)
    return best


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="/work/shared/meshes/homer.obj")
    parser.add_argument("--level", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    import trimesh

    from benchmarks.curved import case_mesh
    from modalviewer.readers import read_mesh_file

    mesh = case_mesh(args.mesh, "loop", args.level)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    print(f"{args.mesh} Loop x{args.level}: {mesh.n_vertices} vertices, {mesh.n_faces} faces")
    print(f"{'format':<12} {'MB':>6} {'modalviewer s':>14} {'trimesh s':>10}")
    with tempfile.TemporaryDirectory() as folder:
        for label, (name, options) in FORMATS.items():
            path = Path(folder) / name
            if options:
                path.write_bytes(trimesh.exchange.ply.export_ply(tm, **options))
            else:
                tm.export(path)
            ours = best_seconds(lambda p=path: read_mesh_file(p), args.repeat)
            theirs = best_seconds(
                lambda p=path: trimesh.load(p, process=False, maintain_order=True), args.repeat
            )
            size = path.stat().st_size / 2**20
            print(f"{label:<12} {size:6.1f} {ours:14.2f} {theirs:10.2f}")


if __name__ == "__main__":
    main()
