"""Fingertips of the hand against fingertips of the bent hand, under each signature.

For each fingertip landmark of ``assets/demo_hand.obj`` (``assets/demo_landmarks.json``)
the distance between shapes (``mv.CrossTables``, eq. 31 with the common scales) to every
vertex of ``assets/demo_hand_bent.obj`` is computed, and the rank of every fingertip of
the bent hand among all its vertices is reported (rank 1 = the closest vertex of all).
The middle finger (``finger1``) is the bent one.  Prints the README table (markdown),
writes the numbers to ``benchmarks/results/hand_correspondence.json`` and, with
``--figure``, renders ``screenshots/cross_hand_vibration_vs_hks.png``.

    python scripts/hand_correspondence.py [--k 100] [--figure]

Spectra come from the viewer's disk cache (``$MODALVIEWER_CACHE``) when present.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import modalviewer as mv  # noqa: E402
from modalviewer.core.cache import SpectrumCache  # noqa: E402

KINDS = {"hks": "laplacian", "vibration": "shells", "feature": "modified_dirichlet"}
LABELS = {"hks": "heat kernel", "vibration": "vibration", "feature": "feature"}
TIPS = ("finger0", "finger1", "finger2", "finger3", "thumb")
NAMES = {"finger0": "index", "finger1": "middle", "finger2": "ring", "finger3": "little",
         "thumb": "thumb"}  # fmt: skip


def spectra(k: int):
    cache = SpectrumCache()
    meshes = [
        mv.load_mesh(ROOT / "assets" / f"{name}.obj") for name in ("demo_hand", "demo_hand_bent")
    ]
    out, seconds = {}, {}
    for kind, operator in KINDS.items():
        pair = []
        for mesh in meshes:
            spec = cache.get(mesh, operator, k)
            if spec is None:
                started = time.perf_counter()
                spec = mv.compute_spectrum(mesh, operator, k)
                seconds[f"{operator} {mesh.n_vertices}"] = time.perf_counter() - started
                cache.put(mesh, spec, k)
            pair.append(spec)
        out[kind] = pair
    return meshes, out, seconds


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--k", type=int, default=100)
    parser.add_argument("--figure", action="store_true")
    args = parser.parse_args()
    landmarks = json.loads((ROOT / "assets" / "demo_landmarks.json").read_text())
    tips_a = [landmarks["demo_hand"][t] for t in TIPS]
    tips_b = [landmarks["demo_hand_bent"][t] for t in TIPS]
    (hand, bent), specs, seconds = spectra(args.k)
    result = {"k": args.k, "n_a": hand.n_vertices, "n_b": bent.n_vertices, "kinds": {}}
    lines = [
        f"| signature | tip of the hand | rank of each tip of the bent hand among its "
        f"{bent.n_vertices} vertices: "
        + " / ".join(NAMES[t] for t in TIPS)
        + " | own tip first among the tips? | best match among the tips (mutual?) "
        "| best match among all vertices: nearest tip (how far) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for kind, (sa, sb) in specs.items():
        started = time.perf_counter()
        tables = mv.CrossTables(sa, sb)
        build = time.perf_counter() - started
        ranks = np.array([mv.distance_ranks(tables.a_to_b(v), tips_b) for v in tips_a])
        matches = tables.mutual_best_matches(tips_a, tips_b)
        result["kinds"][kind] = {
            "times": [float(tables.times[0]), float(tables.times[-1])],
            "tables_seconds": build,
            "ranks": ranks.tolist(),
            "matches_b": matches.matches_b.tolist(),
            "mutual": matches.mutual.tolist(),
        }
        for i, tip in enumerate(TIPS):
            cells = [f"**{r}**" if j == i else str(r) for j, r in enumerate(ranks[i])]
            own_first = bool(np.argmin(ranks[i]) == i)
            match = NAMES[TIPS[tips_b.index(int(matches.matches_b[i]))]]
            best = int(np.argmin(tables.a_to_b(tips_a[i])))
            gap = np.linalg.norm(bent.vertices[tips_b] - bent.vertices[best], axis=1)
            lines.append(
                f"| {LABELS[kind] if i == 0 else ''} | {NAMES[tip]} | {' / '.join(cells)} | "
                f"{'yes' if own_first else 'no'} | {match}"
                f"{' (mutual)' if matches.mutual[i] else ''} | "
                f"{NAMES[TIPS[int(np.argmin(gap))]]} ({gap.min():.2f}) |"
            )
    print("\n".join(lines))
    if seconds:
        print("spectra computed:", ", ".join(f"{k} {v:.1f} s" for k, v in seconds.items()))
    out = ROOT / "benchmarks" / "results" / "hand_correspondence.json"
    out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {out.relative_to(ROOT)}")
    if args.figure:
        from modalviewer.cross_figure import Panel, render_panels

        pick = landmarks["demo_hand"]["finger1"]
        view = {"azimuth": 130.0, "elevation": 20.0}  # from the palm side: the bent tip shows
        panels = [Panel(hand, f"hand: pick on the middle fingertip ({pick})", pick, **view)]
        for kind in ("vibration", "hks"):
            tables = mv.CrossTables(*specs[kind])
            d = tables.a_to_b(pick)
            best = int(np.argmin(d))
            near = min(TIPS, key=lambda t: np.linalg.norm(
                bent.vertices[best] - bent.vertices[landmarks["demo_hand_bent"][t]]))  # fmt: skip
            panels.append(
                Panel(
                    bent,
                    f"bent hand, {LABELS[kind]}: best match {best} ({NAMES[near]} tip)",
                    best,
                    d,
                    **view,
                )  # fmt: skip
            )
        path = render_panels(panels, ROOT / "screenshots" / "cross_hand_vibration_vs_hks.png")
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
