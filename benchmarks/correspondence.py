"""Functional maps on three bases: two poses of the demo hand, the ground truth the identity.

    python -m benchmarks.correspondence [--k 30] [--zoomout 60] [--step 5] [--every 10]

The demo hand (12.9k vertices) and its copy bent by 40 degrees across the palm
(``demo_shapes.bent_pose``, vertex for vertex); for each basis (the Laplacian, E_D^N and
the normal Discrete Shells, scalar modes all) and each descriptor (the wave and the heat
kernel signature of that basis's own spectrum), ``mv.functional_map`` with ``--k`` modes,
then refined by ZoomOut to ``--zoomout`` modes, ``--step`` modes a step.  Mean and median
geodesic error (along the edges, over sqrt(area); ``mv.correspondence_errors``) at every
``--every``-th vertex of B, and the seconds of the map.  Results go to
``benchmarks/results/correspondence.json``.
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
from modalviewer.core.demo_shapes import bent_pose  # noqa: E402

BASES = ("laplacian", "modified_dirichlet", "shells_normal")
ANGLE = 40.0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--k", type=int, default=30)
    parser.add_argument("--zoomout", type=int, default=60)
    parser.add_argument("--step", type=int, default=5)
    parser.add_argument("--every", type=int, default=10)
    args = parser.parse_args(argv)
    a = mv.load_mesh(mv.asset_path("demo_hand.obj"))
    b = bent_pose(a, ANGLE)
    rows = []
    for operator in BASES:
        started = time.perf_counter()
        sa = mv.compute_spectrum(a, operator, k=args.zoomout)
        sb = mv.compute_spectrum(b, operator, k=args.zoomout)
        spectra_s = time.perf_counter() - started
        for descriptors in ("wks", "hks"):
            for zoomout in (None, args.zoomout):
                started = time.perf_counter()
                fm = mv.functional_map(
                    sa, sb, descriptors, k=args.k, zoomout=zoomout, zoomout_step=args.step
                )
                seconds = time.perf_counter() - started
                errors = mv.correspondence_errors(a, fm.point_map, every=args.every)
                row = dict(
                    basis=operator,
                    descriptors=descriptors,
                    k=args.k,
                    zoomout=zoomout,
                    zoomout_step=None if zoomout is None else args.step,
                    mean_error=float(np.nanmean(errors)),
                    median_error=float(np.nanmedian(errors)),
                    map_seconds=round(seconds, 2),
                    spectra_seconds=round(spectra_s, 1),
                )
                print(row, flush=True)
                rows.append(row)
    save_result(
        "correspondence",
        {
            "mesh": "demo_hand.obj",
            "n_vertices": a.n_vertices,
            "bend_degrees": ANGLE,
            "every": args.every,
            "machine": "2 cores shared with other work (load average about 7)",
            "error_unit": "geodesic along the edges / sqrt(area)",
            "rows": rows,
        },
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
