"""Throughput of ``modalviewer batch``: meshes per minute with 1 and 2 local Dask workers
against a plain loop.

    python -m benchmarks.batch [--count 36] [--operator shells] [--k 20]

The meshes are generated: randomly stretched and bumped icospheres (642 and 2562
vertices), tori and plates (``modalviewer.core.primitives``), written as OBJ to a
temporary folder.  Four runs over the same files, each into a fresh store:

- loop: ``load_mesh`` + ``compute_spectrum`` per file in this process, nothing written;
- in-process: ``run_batch(..., workers=0)`` (the same, plus the vibration signature,
  the descriptors and the store's files);
- dask 1 / dask 2: ``run_batch`` on a local cluster of 1 or 2 worker processes (the
  cores shared among them: 2 threads each for 1 worker, 1 each for 2), the cluster's
  start included in the time.

Results go to ``benchmarks/results/batch.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "batch.json"


def _write_obj(mesh, path: Path) -> None:
    with open(path, "w") as fh:
        for x, y, z in mesh.vertices:
            fh.write(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n")
        for a, b, c in mesh.faces + 1:
            fh.write(f"f {a} {b} {c}\n")


def make_meshes(folder: Path, count: int, seed: int = 0) -> list[Path]:
    """``count`` small meshes in ``folder``: stretched and bumped spheres, tori, plates."""
    import modalviewer as mv
    from modalviewer.core import primitives

    rng = np.random.default_rng(seed)
    paths = []
    for i in range(count):
        kind = i % 4
        if kind in (0, 1):
            base = primitives.icosphere(3 + kind)
            v = base.vertices * (1.0 + 0.3 * rng.random(3))
            v = v * (1.0 + 0.05 * np.sin(rng.integers(2, 6) * v[:, [0]]))
            mesh = mv.Mesh(v, base.faces)
        elif kind == 2:
            mesh = primitives.torus(40, 20, minor=0.2 + 0.2 * rng.random())
        else:
            mesh = primitives.grid_plate(30, 30, 1.0, 0.5 + rng.random())
        path = folder / f"shape{i:03d}.obj"
        _write_obj(mesh, path)
        paths.append(path)
    return paths


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=36)
    parser.add_argument("--operator", default="shells")
    parser.add_argument("--k", type=int, default=20)
    args = parser.parse_args(argv)

    import modalviewer as mv
    from modalviewer.collection import run_batch

    runs = []
    load = os.getloadavg()  # the machine is shared: other work slows every run alike
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        folder = tmp / "meshes"
        folder.mkdir()
        paths = make_meshes(folder, args.count)
        vertices = [mv.load_mesh(p).n_vertices for p in paths]
        print(f"{len(paths)} meshes, {min(vertices)} to {max(vertices)} vertices")

        start = time.perf_counter()
        for path in paths:
            mv.compute_spectrum(mv.load_mesh(path), args.operator, args.k)
        runs.append(("loop", time.perf_counter() - start, len(paths)))
        for label, workers in (("in-process", 0), ("dask 1 worker", 1), ("dask 2 workers", 2)):
            start = time.perf_counter()
            summary = run_batch(
                [folder],
                tmp / f"store{workers}",
                args.operator,
                args.k,
                ["vibration"],
                workers=workers,
            )
            seconds = time.perf_counter() - start
            assert not summary.failed, summary.failed
            runs.append((label, seconds, len(summary.computed)))
    rows = []
    loop = runs[0][1]
    for label, seconds, n in runs:
        rate = n / seconds * 60.0
        rows.append(
            {
                "run": label,
                "meshes": n,
                "seconds": round(seconds, 2),
                "meshes_per_minute": round(rate, 1),
                "speed_vs_loop": round(loop / seconds, 2),
            }
        )
        print(
            f"{label:<15} {n} meshes in {seconds:6.1f} s: {rate:6.1f} per minute "
            f"({loop / seconds:.2f} x the loop)"
        )
    result = {
        "date": time.strftime("%Y-%m-%d"),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores",
        "operator": args.operator,
        "k": args.k,
        "signatures": ["vibration"],
        "vertices": [min(vertices), max(vertices)],
        "load_average_before": [round(x, 2) for x in load],
        "runs": rows,
    }
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
