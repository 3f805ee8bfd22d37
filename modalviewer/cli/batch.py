"""``modalviewer batch`` and ``modalviewer similar``: shape collections
(:mod:`modalviewer.collection` does the work)."""

from __future__ import annotations

import sys

from ..core.operators import DISTANCE_KINDS, OPERATOR_NAMES
from .common import COUNT, WEIGHT, Unavailable, number, whole


def _kinds(text: str) -> list[str]:
    import argparse

    kinds = [word.strip() for word in text.split(",") if word.strip()]
    unknown = [kind for kind in kinds if kind not in DISTANCE_KINDS]
    if unknown:
        raise argparse.ArgumentTypeError(
            f"unknown signature {unknown[0]!r}; choose among {', '.join(DISTANCE_KINDS)}"
        )
    return kinds


def add_parsers(sub) -> None:
    b = sub.add_parser(
        "batch",
        help="spectra and signatures of a whole dataset into one store (on Dask)",
    )
    b.add_argument(
        "sources",
        nargs="+",
        metavar="SOURCE",
        help="a folder (searched recursively), a glob pattern, a mesh file, or a list "
        "file (one path per line)",
    )
    b.add_argument("-o", "--output", required=True, metavar="STORE", help="the store folder")
    b.add_argument("--operator", choices=OPERATOR_NAMES, default="laplacian")
    b.add_argument("-k", type=COUNT, default=50, help="number of modes (default: 50)")
    b.add_argument("--bending", type=WEIGHT, default=1.0)
    b.add_argument("--membrane", type=WEIGHT, default=1.0)
    b.add_argument(
        "--signatures",
        type=_kinds,
        default=[],
        metavar="KINDS",
        help=f"comma-separated among {','.join(DISTANCE_KINDS)}: each signature at the "
        "standard scales and its histogram (its operator's spectrum is computed too)",
    )
    where = b.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=whole(0),
        metavar="N",
        help="a local Dask cluster of N worker processes (default: one per core); 0: one "
        "mesh after another in this process, without Dask",
    )
    where.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="an existing Dask scheduler, e.g. tcp://host:8786 (the workers must see the "
        "mesh paths and have modalviewer installed)",
    )
    b.add_argument(
        "--memory-limit",
        type=number(0.0, False),
        metavar="GB",
        help="each local worker's memory limit (default: the machine's memory over the "
        "workers); tasks ask for their estimated memory out of it",
    )
    b.add_argument("--retry-failed", action="store_true", help="retry meshes recorded as failed")
    b.set_defaults(func=batch)
    s = sub.add_parser(
        "similar", help="the meshes of a store nearest to a mesh (Shape-DNA distance)"
    )
    s.add_argument("store")
    s.add_argument("mesh", help="a mesh file, or the name of a mesh in the store")
    s.add_argument("-n", type=COUNT, default=10, help="how many to list (default 10)")
    s.set_defaults(func=similar)


def batch(args) -> int:
    import logging
    import os

    from tqdm import tqdm

    from ..collection.runner import import_distributed, run_batch

    # -k, --workers and --memory-limit are checked by the parser; default: one per core
    workers = (os.cpu_count() or 1) if args.workers is None else args.workers
    if workers > 0 or args.scheduler:
        try:
            import_distributed()
        except ImportError as exc:
            raise Unavailable(str(exc)) from None
    # Dask's own log lines (a cancelled task on Ctrl+C, ...) would break the progress line
    logging.getLogger("distributed").setLevel(logging.ERROR)
    summary = run_batch(
        args.sources,
        args.output,
        args.operator,
        args.k,
        args.signatures,
        args.bending,
        args.membrane,
        workers=workers,
        scheduler=args.scheduler,
        memory_limit=None if args.memory_limit is None else int(args.memory_limit * 2**30),
        retry_failed=args.retry_failed,
        progress=True,
        log=lambda text: tqdm.write(f"modalviewer: note: {text}", sys.stderr),
    )
    print(f"{args.output}: {summary.text()}")  # the summary first, then its details
    for name, error in summary.failed.items():
        print(f"failed: {name}: {error}")
    if summary.failed_before:
        print("recorded failures not tried again: " + ", ".join(summary.failed_before))
    if summary.interrupted:
        sys.stderr.write("modalviewer: interrupted (the store holds every finished mesh)\n")
        return 130
    return 1 if summary.failed else 0


def similar(args) -> int:
    from pathlib import Path

    from ..collection import open_collection

    collection = open_collection(args.store)
    if not collection.names:
        raise ValueError(f"{args.store} holds no meshes")
    query = args.mesh
    if query not in collection and not Path(query).exists():
        raise ValueError(f"{query}: neither a mesh file nor a name in {args.store}")
    ranked = collection.similar(query, args.n)
    print(
        f"nearest to {query} in {args.store} ({collection.operator}, {collection.k} modes; "
        "Shape-DNA distance):"
    )
    width = max(len(name) for name, _ in ranked)
    for rank, (name, distance) in enumerate(ranked, 1):
        print(f"{rank:3d}. {name:<{width}}  {distance:.6g}")
    return 0
