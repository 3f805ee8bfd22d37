"""Exact spectra on curved meshes: time and peak memory, each run in its own process.

    python -m benchmarks.curved --cases spot:loop:2 hand:loop:2 -k 100
    python -m benchmarks.curved --operators laplacian --keep-others   # re-measure some rows

A case is ``asset:scheme:level``: a bundled mesh (``spot``: the cow, thin legs, ears and
horns; ``hand``: ``demo_hand.obj``, five thin fingers; ``part``:
``demo_machined_part.obj``, a machined part with sharp edges and holes) or a mesh file
(named in the results by its stem) subdivided
``level`` times, by Loop (``loop``, smooth) or by splitting each triangle in four in its
plane (``flat``: the part keeps its sharp edges).  Writes
``benchmarks/results/curved.json``.  Each (case, operator) runs in a fresh Python
process so its peak resident memory is its own.  The child processes compute with
the memory settings of the viewer's and the command line's compute processes
(:func:`modalviewer.core.memory.prepare_compute_process`), so their peaks are what
a user's computation needs.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


CHILD = """
import json, resource, sys, time
from modalviewer.core.memory import prepare_compute_process
prepare_compute_process()
import numpy as np
import modalviewer as mv
asset, scheme, level = sys.argv[1], sys.argv[2], int(sys.argv[3])
operator, k = sys.argv[4], int(sys.argv[5])
from benchmarks.curved import case_mesh
mesh = case_mesh(asset, scheme, level)
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
t = time.perf_counter()
spec = mv.compute_spectrum(mesh, operator, k)
seconds = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
nonzero = spec.eigenvalues[~spec.zero_mode_mask()]
print(json.dumps({"vertices": mesh.n_vertices, "seconds": seconds, "peak_mb": peak,
                  "mesh_mb": before, "eigenvalues": [float(x) for x in nonzero]}))
"""


ASSETS = {"spot": "spot.obj", "hand": "demo_hand.obj", "part": "demo_machined_part.obj"}
SCHEMES = {"loop": "Loop", "flat": "flat"}
DEFAULT_CASES = ["spot:loop:2", "spot:loop:3", "hand:loop:2", "part:flat:3"]


def case_mesh(path: str, scheme: str, level: int):
    """The mesh of a case: ``path`` (a bundled asset's file name, or a mesh file)
    subdivided ``level`` times by ``scheme`` ("loop", or "flat": each triangle split in
    four in its plane)."""
    import trimesh

    import modalviewer as mv

    base = mv.load_mesh(path if Path(path).is_file() else mv.asset_path(path))
    v, f = base.vertices, base.faces
    if scheme == "loop" and level > 0:
        v, f = trimesh.remesh.subdivide_loop(v, f, iterations=level)
    else:
        for _ in range(level):
            v, f = trimesh.remesh.subdivide(v, f)
    return mv.Mesh(v, f)


def case_name(case: tuple[str, str, int]) -> str:
    """The results file's name of a case, e.g. "hand Loop x2" (a file: its stem)."""
    asset, scheme, level = case
    return f"{Path(asset).stem} {SCHEMES[scheme]} x{level}"


def _position(order: list[str], name: str) -> int:
    return order.index(name) if name in order else len(order)


def parse_case(text: str) -> tuple[str, str, int]:
    """``asset:scheme:level`` -> (asset, scheme, level), with a clear error; the asset
    is a bundled one's short name or a mesh file's path (meshes not bundled, e.g. other
    scans)."""
    try:
        asset, scheme, level = text.rsplit(":", 2)
        known = asset in ASSETS or Path(asset).is_file()
        if not known or scheme not in SCHEMES or int(level) < 0:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: a case is asset:scheme:level with asset one of {sorted(ASSETS)} "
            f"or a mesh file, scheme one of {sorted(SCHEMES)} and level >= 0, "
            "e.g. hand:loop:2"
        ) from None
    return asset, scheme, int(level)


def case_path(asset: str) -> str:
    """The mesh file of a case's asset: a bundled asset's file name, or the path given."""
    return ASSETS.get(asset, str(Path(asset).resolve()))


def run(case: tuple[str, str, int], operator: str, k: int) -> dict:
    asset, scheme, level = case
    out = subprocess.run(
        [
            sys.executable,
            "-c",
            CHILD,
            case_path(asset),
            scheme,
            str(level),
            operator,
            str(k),
        ],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    from benchmarks.run import add_keep_others, kept_rows, save_result
    from modalviewer.core.operators import OPERATOR_NAMES

    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument(
        "--cases", type=parse_case, nargs="+", default=[parse_case(c) for c in DEFAULT_CASES]
    )
    p.add_argument("--operators", nargs="+", default=["laplacian", "modified_dirichlet", "shells"])
    p.add_argument("-k", type=int, default=100)
    add_keep_others(p, "other cases or operators")
    args = p.parse_args(argv)
    names = {case_name(case) for case in args.cases}
    rows = kept_rows(  # rows of what is not run now stay
        "curved",
        args.keep_others,
        lambda r: r["mesh"] in names and r["operator"] in args.operators,
    )
    order = [case_name(parse_case(c)) for c in DEFAULT_CASES]
    operators = list(OPERATOR_NAMES)  # a mesh's rows in the registry's order
    for case in args.cases:
        for operator in args.operators:
            exact = run(case, operator, args.k)
            row = {
                "mesh": case_name(case),
                "vertices": exact["vertices"],
                "operator": operator,
                "k": args.k,
                "exact_seconds": round(exact["seconds"], 2),
                "exact_peak_mb": round(exact["peak_mb"]),
            }
            rows.append(row)
            print(json.dumps(row), flush=True)
            rows.sort(
                key=lambda r: (_position(order, r["mesh"]), _position(operators, r["operator"]))
            )
            save_result("curved", {"rows": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
