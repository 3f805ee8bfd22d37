"""Reading mesh files: modalviewer's strict readers against trimesh's, per format.

    python -m benchmarks.readers [--mesh MESH] [--level 4] [--repeat 3]

The mesh is ``benchmarks.curved.case_mesh(mesh, "loop", level)`` (by default the bundled
spot, Loop-subdivided four times: 749,570 vertices), written by trimesh
as OBJ, binary PLY, ASCII PLY, binary STL and OFF to a temporary folder.  Each file is
read ``--repeat`` times in this process by ``modalviewer.readers.read_mesh_file`` and by
``trimesh.load(process=False, maintain_order=True)``; the table gives the best time of
each.  trimesh keeps STL's corners as they are (three vertices per triangle); the
strict reader merges them into the distinct positions, as a vertex number needs.
Writes ``benchmarks/results/readers.json``.
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


def table(data: dict) -> str:
    lines = [
        "| format | file MB | modalviewer s | trimesh s | ratio |",
        "|---|---:|---:|---:|---:|",
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['format']} | {r['mb']:.1f} | {r['modalviewer']:.2f} | {r['trimesh']:.2f} "
            f"| {r['modalviewer'] / r['trimesh']:.2f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="spot.obj")
    parser.add_argument("--level", type=int, default=4)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    import trimesh

    from benchmarks.curved import case_mesh
    from benchmarks.run import save_result
    from modalviewer.readers import read_mesh_file

    mesh = case_mesh(args.mesh, "loop", args.level)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    print(f"{args.mesh} Loop x{args.level}: {mesh.n_vertices} vertices, {mesh.n_faces} faces")
    rows = []
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
            rows.append({"format": label, "mb": size, "modalviewer": ours, "trimesh": theirs})
            print(f"{label:<12} {size:6.1f} {ours:8.2f} {theirs:8.2f}", flush=True)
    name = f"{Path(args.mesh).stem} Loop x{args.level}"
    data = {"mesh": name, "vertices": mesh.n_vertices, "repeat": args.repeat, "rows": rows}
    save_result("readers", data)
    print(table(data))


if __name__ == "__main__":
    main()
