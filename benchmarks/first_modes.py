"""Exact modes as they converge: when the first modes arrive, and what handing them over
costs the whole solve, against the solver of a baseline commit in the same run.

    python -m benchmarks.first_modes --cases spot:loop:2 path/to/cheburashka.obj:loop:2 \
        --operators laplacian shells -k 100 --first 10 --baseline 2420880

A case is ``mesh:scheme:level[:zup]``: a bundled asset's file name (``spot``) or a mesh
file, subdivided ``level`` times by Loop (``loop``) or in its plane (``flat``), and turned
so that its up axis is z (``zup``, as scans often are).  For each case and operator, each
in a fresh process with the compute process's memory settings:

- ``handover``: ``compute_spectrum(mesh, operator, k, on_modes=...)``, with the time at
  which the first ``--first`` modes (null vectors counted, as a k = 10 solve counts them)
  and the first ``--first`` non-zero modes were handed over, and the total;
- ``baseline``: the same solve by the baseline commit's code (``git archive``), which has
  no hand-over;
- ``few``: a separate ``--first``-mode solve by this code.

The runs of one row alternate (handover, baseline, few), ``--repeats`` rounds of them,
so that a drift of the machine's speed shows in all three; each figure is the median of
its rounds.  Writes ``benchmarks/results/first_modes.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


CHILD = """
import json, resource, sys, time
try:
    from modalviewer.core.memory import prepare_compute_process
except ImportError:  # a baseline from before the memory modules were one
    from modalviewer.processes.memory import prepare_compute_process
prepare_compute_process()
import numpy as np
import modalviewer as mv
from benchmarks.first_modes import case_mesh
path, scheme, level, zup = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4] == "1"
operator, k, first, handover = sys.argv[5], int(sys.argv[6]), int(sys.argv[7]), sys.argv[8]
mesh = case_mesh(path, scheme, level, zup)
arrivals = []
t = time.perf_counter()
def on_modes(spec):
    nonzero = int(np.count_nonzero(~spec.zero_mode_mask()))
    arrivals.append([time.perf_counter() - t, spec.k, nonzero])
kwargs = {"on_modes": on_modes} if handover == "1" else {}
spec = mv.compute_spectrum(mesh, operator, k, **kwargs)
seconds = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"vertices": mesh.n_vertices, "seconds": seconds, "peak_mb": peak,
                  "arrivals": arrivals,
                  "eigenvalues": [float(x) for x in spec.eigenvalues]}))
"""


def case_mesh(path: str, scheme: str, level: int, zup: bool = False):
    """The mesh of a case (see the module's docstring): :func:`benchmarks.curved.case_mesh`
    (a bundled asset may be named without its ".obj"), turned so that z is up."""
    import modalviewer as mv
    from benchmarks.curved import case_mesh as subdivided

    if not Path(path).is_file() and not Path(path).suffix:
        path = f"{path}.obj"
    mesh = subdivided(path, scheme, level)
    if not zup:
        return mesh
    y_up_to_z_up = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    return mv.Mesh(mesh.vertices @ y_up_to_z_up, mesh.faces)


def parse_case(text: str) -> tuple[str, str, int, bool]:
    parts = text.split(":")
    if len(parts) not in (3, 4) or parts[1] not in ("loop", "flat") or not parts[2].isdigit():
        raise argparse.ArgumentTypeError(f"a case is mesh:loop|flat:level[:zup], got {text!r}")
    if len(parts) == 4 and parts[3] != "zup":
        raise argparse.ArgumentTypeError(f"the fourth part of a case can only be zup: {text!r}")
    return parts[0], parts[1], int(parts[2]), len(parts) == 4


def case_name(case: tuple[str, str, int, bool]) -> str:
    path, scheme, level, zup = case
    name = f"{Path(path).stem} {'Loop' if scheme == 'loop' else 'flat'} x{level}"
    return name + (", z up" if zup else "")


def baseline_tree(commit: str) -> Path:
    """The baseline commit's package and benchmarks, extracted into a temporary folder."""
    folder = Path(tempfile.mkdtemp(prefix="modalviewer-baseline-"))
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", commit, "modalviewer"],
        check=True,
        capture_output=True,
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    # the child imports case_mesh from this code's benchmarks
    (folder / "benchmarks").symlink_to(ROOT / "benchmarks")
    (folder / "assets").symlink_to(ROOT / "assets")
    return folder


def run_child(tree: Path, case, operator: str, k: int, first: int, handover: bool) -> dict:
    path, scheme, level, zup = case
    path = str(Path(path).resolve()) if Path(path).is_file() else path
    env = dict(os.environ, PYTHONPATH=str(tree))
    argv = [path, scheme, str(level), "1" if zup else "0", operator, str(k), str(first)]
    child = subprocess.run(
        [sys.executable, "-c", CHILD, *argv, "1" if handover else "0"],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
    )
    if child.returncode != 0:
        raise RuntimeError(f"the benchmark's child failed:\n{child.stderr}")
    return json.loads(child.stdout.strip().splitlines()[-1])


def first_arrival(arrivals: list, first: int, column: int) -> float | None:
    """Seconds until at least ``first`` modes (column 1) or non-zero modes (column 2)."""
    return next((a[0] for a in arrivals if a[column] >= first), None)


def measure(case, operator: str, k: int, first: int, baseline: Path, repeats: int) -> dict:
    """One row: ``repeats`` rounds of (handover, baseline, few), each figure the median
    of its rounds; the seconds of every round are kept too."""
    rounds = []
    for _ in range(repeats):
        rounds.append(
            (
                run_child(ROOT, case, operator, k, first, handover=True),
                run_child(baseline, case, operator, k, first, handover=False),
                run_child(ROOT, case, operator, first, first, handover=False),
            )
        )
    new, old, _ = rounds[0]
    differences = [
        abs(a - b) / abs(b)
        for a, b in zip(new["eigenvalues"], old["eigenvalues"], strict=True)
        if b > 0
    ]

    def median(values) -> float:
        return float(np.median(list(values)))

    return {
        "case": case_name(case),
        "operator": operator,
        "vertices": new["vertices"],
        "k": k,
        "first": first,
        "repeats": repeats,
        "seconds_first": median(first_arrival(n["arrivals"], first, 1) for n, _, _ in rounds),
        "seconds_first_nonzero": median(
            first_arrival(n["arrivals"], first, 2) for n, _, _ in rounds
        ),
        "seconds_total": median(n["seconds"] for n, _, _ in rounds),
        "seconds_baseline": median(o["seconds"] for _, o, _ in rounds),
        "seconds_few": median(f["seconds"] for _, _, f in rounds),
        "seconds_total_runs": [n["seconds"] for n, _, _ in rounds],
        "seconds_baseline_runs": [o["seconds"] for _, o, _ in rounds],
        "total_over_baseline_runs": [n["seconds"] / o["seconds"] for n, o, _ in rounds],
        "peak_mb": median(n["peak_mb"] for n, _, _ in rounds),
        "peak_mb_baseline": median(o["peak_mb"] for _, o, _ in rounds),
        "handovers": len(new["arrivals"]),
        "largest_eigenvalue_difference": max(differences, default=0.0),
    }


def _thousands(count: int) -> str:
    return f"{count:,}".replace(",", "\u00a0")


def paired_ratio(row: dict) -> float:
    """The median over the rounds of the whole run's time over the baseline's: each
    round's two runs are adjacent, so their ratio leaves out the machine's drift between
    rounds (one round's ratio alone varies by about a tenth here)."""
    return float(np.median(row["total_over_baseline_runs"]))


def table(data: dict) -> str:
    """The Markdown table of the results."""
    lines = [
        f"| mesh | vertices | operator | first {data['first']} modes | first {data['first']} "
        f"non-zero | all {data['k']} | share of all | {data['first']}-mode solve | "
        f"all {data['k']}, baseline | total / baseline, paired | peak / baseline | rounds |",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['case']} | {_thousands(r['vertices'])} | {r['operator']} | "
            f"{r['seconds_first']:.1f} s "
            f"| {r['seconds_first_nonzero']:.1f} s | {r['seconds_total']:.1f} s | "
            f"{r['seconds_first'] / r['seconds_total']:.2f} | {r['seconds_few']:.1f} s | "
            f"{r['seconds_baseline']:.1f} s | {paired_ratio(r):.2f} | "
            f"{r['peak_mb'] / r['peak_mb_baseline']:.2f} | {r['repeats']} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", type=parse_case, default=[parse_case("spot:loop:2")])
    parser.add_argument("--operators", nargs="+", default=["laplacian", "shells"])
    parser.add_argument("-k", type=int, default=100)
    parser.add_argument("--first", type=int, default=10)
    parser.add_argument("--baseline", default="2420880", help="the commit to compare with")
    parser.add_argument("--repeats", type=int, default=3, help="rounds per row (medians)")
    from benchmarks.run import add_keep_others, kept_rows, save_result  # imports the package

    add_keep_others(parser, "other cases or operators")
    args = parser.parse_args(argv)
    now = {(case_name(case), operator) for case in args.cases for operator in args.operators}
    kept = kept_rows("first_modes", args.keep_others, lambda r: (r["case"], r["operator"]) in now)
    baseline = baseline_tree(args.baseline)
    rows = []
    for case in args.cases:
        for operator in args.operators:
            rows.append(measure(case, operator, args.k, args.first, baseline, args.repeats))
            print(json.dumps(rows[-1]), flush=True)
    rows = sorted(kept + rows, key=lambda r: (r["case"], r["operator"]))
    data = {"k": args.k, "first": args.first, "baseline": args.baseline, "rows": rows}
    save_result("first_modes", data)
    print(table(data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
