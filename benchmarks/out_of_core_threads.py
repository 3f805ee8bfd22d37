"""Out-of-core solves on one MKL thread against MKL's default threads, in one run.

    python -m benchmarks.out_of_core_threads --cases spot:loop:3 --operator laplacian -k 50

When the factor does not fit the memory limit, PARDISO keeps it in a file and every
solve reads it back.  ``modalviewer.core.factor`` runs those solves on one MKL thread;
this benchmark compares that with the parallel substitution MKL would use otherwise
(the baseline: the one-thread switch replaced by a no-op), each in a fresh process,
alternating the two ``--repeat`` times, and an in-core solve of the same problem for
reference.  Each run is ``compute_spectrum`` with ``MODALVIEWER_MEMORY_LIMIT_MB`` set low
enough to push the factor out of core.  Writes
``benchmarks/results/out_of_core_threads.json``.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.first_modes import case_name, parse_case  # noqa: E402
from benchmarks.run import save_result  # noqa: E402

CHILD = """
import contextlib, json, os, sys, time
path, scheme, level, zup, operator, k, variant, limit = sys.argv[1:9]
if limit != "none":
    os.environ["MODALVIEWER_MEMORY_LIMIT_MB"] = limit
from modalviewer.core import factor
from modalviewer.core.memory import prepare_compute_process
prepare_compute_process()
import modalviewer as mv
from benchmarks.first_modes import case_mesh
if variant == "default_threads":
    factor._one_mkl_thread = lambda lib: contextlib.nullcontext()
mesh = case_mesh(path, scheme, int(level), zup == "1")
t = time.perf_counter()
spec = mv.compute_spectrum(mesh, operator, int(k))
seconds = time.perf_counter() - t
print(json.dumps({"vertices": mesh.n_vertices, "seconds": seconds,
                  "out_of_core": bool(spec.parameters["factor_out_of_core"])}))
"""

VARIANTS = ("one_thread", "default_threads")


def _run(case, operator: str, k: int, variant: str, limit: str) -> dict:
    path, scheme, level, zup = case
    argv = [path, scheme, str(level), "1" if zup else "0", operator, str(k), variant, limit]
    out = subprocess.run(
        [sys.executable, "-c", CHILD, *argv], cwd=ROOT, capture_output=True, text=True
    )
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-2000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def table(data: dict) -> str:
    lines = [
        "| mesh | vertices | operator | modes | in core | out of core, one thread "
        "| out of core, MKL's threads | ratio |",
        "|---|---:|---|---:|---:|---:|---:|---:|",
    ]
    for r in data["rows"]:
        one, default = min(r["one_thread"]), min(r["default_threads"])
        lines.append(
            f"| {r['case']} | {r['vertices']:,} | {r['operator']} | {r['k']} "
            f"| {r['in_core']:.1f} s | {one:.1f} s | {default:.1f} s | {one / default:.2f} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", type=parse_case, default=[parse_case("spot:loop:3")])
    parser.add_argument("--operator", default="laplacian")
    parser.add_argument("-k", type=int, default=50)
    parser.add_argument("--limit-mb", default="1", help="the memory limit of the runs (MB)")
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args(argv)
    rows = []
    for case in args.cases:
        runs = {variant: [] for variant in VARIANTS}
        for _ in range(args.repeat):
            for variant in VARIANTS:
                run = _run(case, args.operator, args.k, variant, args.limit_mb)
                if not run["out_of_core"]:
                    raise SystemExit(
                        f"{case_name(case)}: the factor stayed in core; lower --limit-mb"
                    )
                runs[variant].append(run["seconds"])
                print(case_name(case), variant, f"{run['seconds']:.1f} s", flush=True)
        in_core = _run(case, args.operator, args.k, "one_thread", "none")
        rows.append(
            {
                "case": case_name(case),
                "vertices": in_core["vertices"],
                "operator": args.operator,
                "k": args.k,
                "in_core": in_core["seconds"],
                **runs,
            }
        )
    data = {"limit_mb": float(args.limit_mb), "rows": rows}
    save_result("out_of_core_threads", data)
    print(table(data))
    return 0


if __name__ == "__main__":
    sys.exit(main())
