"""The batch: every mesh of a dataset into one store (:mod:`.store`), on a Dask cluster
(``dask.distributed``: a local one, or an existing scheduler) or one mesh after another
in this process."""

from __future__ import annotations

import glob
import json
import logging
import os
import re
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.operators import DISTANCE_KINDS, operator_for_distance, operator_info, signature_kind
from ..core.spectrum import SPECTRUM_ARRAYS, Spectrum, spectrum_arrays
from .store import (
    HISTOGRAM_EDGES,
    HISTOGRAM_SCALES,
    STORE_FORMAT,
    STORE_VERSION,
    entry_key,
    file_stat,
    prepare_store,
    read_entry,
    read_json,
    rebuild_index,
    shape_dna,
    write_entry,
    write_error,
)


def find_meshes(sources: Iterable[str | os.PathLike]) -> list[Path]:
    """The mesh files of ``sources``, each once in the order found: folders (searched
    recursively for the extensions :func:`.io.load_mesh` reads, less
    :data:`.io.AMBIGUOUS_EXTENSIONS`), glob patterns, mesh files, and list files (any
    other file: one path per line, relative to the list's folder; blanks and ``#``
    comments skipped).  ValueError for a source that matches nothing."""
    from ..io import is_mesh_file

    found: list[Path] = []
    for source in sources:
        text = str(source)
        path = Path(text)
        if path.is_dir():
            files = [p for p in sorted(path.rglob("*")) if is_mesh_file(p, True) and p.is_file()]
            if not files:
                raise ValueError(f"{text}: no mesh files in this folder")
            found += files
        elif path.is_file() and is_mesh_file(path):
            found.append(path)
        elif path.is_file():
            for line in path.read_text(encoding="utf-8").splitlines():
                line = line.strip()
                if line and not line.startswith("#"):
                    found.append(path.parent / line)  # an absolute line stays absolute
        elif glob.has_magic(text):
            matches = [p for p in sorted(map(Path, glob.glob(text, recursive=True))) if p.is_file()]
            if not matches:
                raise ValueError(f"{text}: the pattern matches no file")
            found += matches
        else:
            raise ValueError(f"{text}: no such file or folder")
    unique: dict[Path, Path] = {}
    for p in found:
        unique.setdefault(p.resolve(), p)
    return list(unique.values())


def mesh_names(paths: Sequence[Path]) -> list[str]:
    """A name per path, unique: the file's stem, or where stems repeat the path from
    the folder the repeated files share, with ``--`` for the folder separator, and the
    file's suffix where that is still the same (``cow.obj`` and ``cow.stl`` side by
    side)."""
    stems = [p.stem for p in paths]
    names = []
    for p, stem in zip(paths, stems, strict=True):
        if stems.count(stem) == 1:
            names.append(stem)
            continue
        same = [q.resolve() for q, s in zip(paths, stems, strict=True) if s == stem]
        root = Path(os.path.commonpath([str(q.parent) for q in same]))
        here = p.resolve()
        rel = here.relative_to(root)
        twins = sum(q.with_suffix("") == here.with_suffix("") for q in same)
        names.append("--".join(rel.parts if twins > 1 else rel.with_suffix("").parts))
    # safe file names: letters, digits and -_.+ kept, others "_", no leading dot
    safe = ["".join(c if c.isalnum() or c in "-_.+" else "_" for c in n) for n in names]
    return [name.lstrip(".") or "mesh" for name in safe]


def _parameters(operator, k, signatures, bending, membrane) -> dict:
    operator_info(operator)  # ValueError for an unknown operator
    if int(k) < 1:
        raise ValueError("-k must be at least 1")
    kinds = sorted(set(signatures))
    for kind in kinds:
        if kind not in DISTANCE_KINDS:
            raise ValueError(
                f"unknown signature {kind!r}; choose among {', '.join(DISTANCE_KINDS)}"
            )
    return {
        "operator": operator,
        "k": int(k),
        "bending": float(bending),
        "membrane": float(membrane),
        "signatures": kinds,
        "histogram_edges": [float(x) for x in HISTOGRAM_EDGES],
        "histogram_scales": HISTOGRAM_SCALES,
        "version": STORE_VERSION,
    }


def vertex_count_hint(path: Path) -> int:
    """A quick estimate of a mesh file's vertex count, without reading the mesh: the
    header of PLY and OFF, the ``v`` lines of OBJ, the triangle count of binary STL,
    else the file size over 40 bytes."""
    path = Path(path)
    size, suffix = path.stat().st_size, path.suffix.lower()
    try:
        with open(path, "rb") as fh:
            data = fh.read() if suffix == ".obj" else fh.read(4096)
    except OSError:
        data = b""
    if suffix == ".obj":
        return data.count(b"\nv ") + data.startswith(b"v ")
    if suffix == ".stl" and size > 84:
        return max(3, (size - 84) // 50 // 2)
    # PLY: its vertex element; OFF: the first line of numbers (comments removed)
    counts = {".ply": rb"^element vertex (\d+)", ".off": rb"^\s*(\d+)\s"}
    found = suffix in counts and re.search(counts[suffix], re.sub(rb"#.*", b"", data), re.M)
    return int(found.group(1)) if found else max(3, size // 40)


def memory_estimate(n_vertices: int, parameters: dict) -> int:
    """Bytes one mesh's task is expected to need at its peak: the largest of its spectrum
    computations (:meth:`~.core.operators.OperatorInfo.predicted_peak_mb`) plus the
    kept spectra and signatures."""
    k = parameters["k"]
    peak, kept = 0.0, 0.0
    for op in _operators(parameters):
        info = operator_info(op)
        n = info.unknowns(n_vertices)
        kept += 8.0 * n * min(k, n)
        peak = max(peak, info.predicted_peak_mb(n_vertices, min(k, n)) * 2**20)
    kept += 8.0 * n_vertices * 100 * len(parameters["signatures"])
    return int(peak + kept + 200 * n_vertices + 50e6)


def _operators(parameters: dict) -> list[str]:
    """The batch's operator, then those its signatures need, each once."""
    kinds = parameters["signatures"]
    return list(dict.fromkeys([parameters["operator"], *map(operator_for_distance, kinds)]))


def _histogram(spec: Spectrum, area: float, kind: str = "heat") -> np.ndarray:
    """(HISTOGRAM_SCALES, bins) area-weighted histograms of log10(A S_t(v) / Z(t)), or
    for ``kind="wks"`` of log10(A W_E(v)) at energies of the default band."""
    from ..core.signatures import default_energies, default_times, signature, wks_sigma

    scales = default_energies(spec) if kind == "wks" else default_times(spec)
    picked = scales[np.linspace(0, len(scales) - 1, HISTOGRAM_SCALES).round().astype(int)]
    if kind == "wks":
        _, w = signature(spec, kind="wks", energies=picked, sigma=wks_sigma(scales))
        h = area * w
    else:
        _, s = signature(spec, times=picked)  # (n, S)
        z = np.exp(-np.outer(spec.eigenvalues[~spec.zero_mode_mask()], picked)).sum(axis=0)
        h = area * s / z
    logs = np.log10(np.clip(h, 10.0 ** HISTOGRAM_EDGES[0], 10.0 ** HISTOGRAM_EDGES[-1]))
    share = spec.mass / spec.mass.sum()
    return np.stack(
        [np.histogram(logs[:, j], HISTOGRAM_EDGES, weights=share)[0] for j in range(len(picked))]
    )


def process_mesh(path: str, parameters: dict, known_key: str | None = None) -> dict:
    """The task of one mesh: read it, compute its spectra, signatures and descriptors.
    Returns ``{"status": "computed", "arrays": {...}, "entry": {...}}``, ``{"status":
    "unchanged"}`` if its key equals ``known_key``, or ``{"status": "failed", "error":
    "..."}``: errors are results, so one bad file does not stop the batch."""
    import warnings

    from ..core.pipeline import compute_spectrum
    from ..core.signatures import signature
    from ..io import load_mesh

    start = time.perf_counter()
    try:
        mesh = load_mesh(path)
        key = entry_key(mesh.hash, parameters)
        if known_key is not None and key == known_key:
            return {"status": "unchanged", "key": key}
        area = mesh.total_area
        arrays: dict[str, np.ndarray] = {}
        spectra: dict[str, Spectrum] = {}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            weights = parameters["bending"], parameters["membrane"]
            for op in _operators(parameters):
                spectra[op] = compute_spectrum(mesh, op, parameters["k"], *weights)
            main = spectra[parameters["operator"]]
            arrays.update(spectrum_arrays(main))  # a spectrum file, and more
            for op, spec in spectra.items():
                if spec is not main:  # a signature's own operator: OP.eigenvalues, ...
                    arrays.update({f"{op}.{p}": getattr(spec, p) for p in SPECTRUM_ARRAYS})
                    arrays[f"{op}.parameters"] = np.array(json.dumps(spec.parameters))
            arrays["shape_dna"] = shape_dna(main, area)
            for kind in parameters["signatures"]:
                spec = spectra[operator_for_distance(kind)]
                sig = signature(spec, kind=signature_kind(kind))
                arrays[f"sig.{kind}.times"], arrays[f"sig.{kind}.values"] = sig
                arrays[f"hist.{kind}"] = _histogram(spec, area, signature_kind(kind))
        entry = {
            "format": STORE_FORMAT + "-entry",
            "version": STORE_VERSION,
            "source": str(Path(path).resolve()),
            "stat": file_stat(Path(path)),
            "mesh_hash": mesh.hash,
            "key": key,
            "parameters": parameters,
            "area": area,
            "n_vertices": mesh.n_vertices,
            "n_faces": int(len(mesh.faces)),
            "seconds": time.perf_counter() - start,
            "warnings": sorted({str(w.message) for w in caught}),
        }
        return {"status": "computed", "arrays": arrays, "entry": entry}
    except Exception as exc:  # a bad file or a failed solve is recorded, not raised
        return {"status": "failed", "error": _one_line(exc)}


def _one_line(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


@dataclass
class BatchSummary:
    """What a batch did: mesh names by outcome, and the time it took."""

    computed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    failed: dict[str, str] = field(default_factory=dict)
    failed_before: list[str] = field(default_factory=list)
    """The skipped meshes that failed in an earlier run (``retry_failed`` retries them)."""
    seconds: float = 0.0
    interrupted: bool = False

    def text(self) -> str:
        rate = len(self.computed) / self.seconds * 60.0 if self.seconds > 0 else 0.0
        words = f"{len(self.computed)} computed, {len(self.skipped)} already done"
        if self.failed_before:  # skipped as done, but they are failures
            words += (
                f" ({len(self.failed_before)} of them recorded failures, not tried again: "
                "--retry-failed)"
            )
        words += f", {len(self.failed)} failed, in {self.seconds:.1f} s"
        if self.computed:
            words += f" ({rate:.1f} meshes per minute)"
        return ("interrupted: " if self.interrupted else "") + words


def run_batch(
    sources: Iterable[str | os.PathLike],
    store: str | os.PathLike,
    operator: str = "laplacian",
    k: int = 50,
    signatures: Sequence[str] = (),
    bending: float = 1.0,
    membrane: float = 1.0,
    workers: int = 1,
    scheduler: str | None = None,
    client=None,
    memory_limit: int | None = None,
    retry_failed: bool = False,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
) -> BatchSummary:
    """Compute every mesh of ``sources`` (:func:`find_meshes`) into ``store``, one task
    per mesh, on ``client`` (a ``dask.distributed.Client``), else the ``scheduler``, else a
    local cluster of ``workers`` single-threaded processes (0: in this process, no Dask).
    Each task asks for its :func:`memory_estimate` of the workers' ``memory`` resource
    (local workers offer their ``memory_limit``), so that two big meshes do not start
    together on a worker that cannot hold both.  Current results are skipped, and
    recorded failures unless ``retry_failed``; results are written as they arrive and the
    index rebuilt at the end, also when interrupted.  CollectionError if the store holds
    results of other parameters.  ``progress``: a tqdm bar on stderr; ``log(text)`` gets
    notes."""
    from tqdm import tqdm

    store = Path(store)
    parameters = _parameters(operator, k, signatures, bending, membrane)
    paths = find_meshes(sources)
    names = mesh_names(paths)
    prepare_store(store, parameters)
    log = log or (lambda text: None)
    summary = BatchSummary()
    start = time.perf_counter()
    todo: list[tuple[str, Path, str | None]] = []
    for name, path in zip(names, paths, strict=True):
        status, known = _done(store, name, path, parameters, retry_failed)
        if status == "todo":
            todo.append((name, path, known))
        else:
            summary.skipped.append(name)
            if status == "failed":
                summary.failed_before.append(name)
    bar = tqdm(
        total=len(paths),
        initial=len(summary.skipped),  # the rate is this run's
        disable=not progress,
        file=sys.stderr,
        unit="mesh",
        ascii=".#",
        smoothing=0,
        bar_format="[{bar:30}] {n_fmt}/{total_fmt} meshes{postfix}, {rate_fmt}, {remaining} left",
    )

    def take(name: str, path: Path, result: dict) -> None:
        if result["status"] == "computed":
            write_entry(store, name, result)
            summary.computed.append(name)
        elif result["status"] == "unchanged":
            summary.skipped.append(name)
        else:
            write_error(store, name, path, parameters, result["error"])
            summary.failed[name] = result["error"]
            bar.set_postfix_str(f"{len(summary.failed)} failed", refresh=False)
        bar.update()

    try:
        if workers == 0 and client is None and scheduler is None:
            for name, path, known in todo:
                take(name, path, process_mesh(str(path), parameters, known))
        elif todo:
            _run_dask(todo, parameters, take, workers, scheduler, client, memory_limit, log)
    except KeyboardInterrupt:
        summary.interrupted = True
    finally:
        bar.close()  # the line ends, also where the batch stopped short
        summary.seconds = time.perf_counter() - start
        rebuild_index(store)
    return summary


def _done(store: Path, name: str, path: Path, parameters: dict, retry_failed: bool):
    """("done", None) if ``name`` has a current result, ("failed", None) if a current
    recorded failure (not retried), else ("todo", the stored key or None)."""
    entry = read_entry(store / "meshes" / f"{name}.npz")
    stat = file_stat(path)
    if entry is not None:
        same = entry.get("parameters") == parameters and entry.get("source") == str(path.resolve())
        if same and entry.get("stat") == stat:
            return "done", None
        return "todo", entry.get("key") if entry.get("parameters") == parameters else None
    record = {} if retry_failed else read_json(store / "errors" / f"{name}.json") or {}
    if record.get("parameters") == parameters and record.get("stat") == stat:
        return "failed", None
    return "todo", None


def import_distributed():
    """``dask.distributed``, or an ImportError saying how to install it or run without it."""
    try:
        import distributed
    except ImportError:
        raise ImportError(
            "Dask is not installed: pip install 'modalviewer[batch]' (or --workers 0: "
            "one mesh after another in this process)"
        ) from None
    return distributed


def _run_dask(todo, parameters, take, workers, scheduler, client, memory_limit, log) -> None:
    distributed = import_distributed()
    with ExitStack() as own:  # a client or cluster made here is closed here
        if client is None and scheduler is not None:
            client = distributed.Client(scheduler)
            own.callback(client.close)
        elif client is None:
            from ..core.memory import physical_memory_mb

            workers = max(1, int(workers))
            physical = (physical_memory_mb() or 0.0) * 2**20
            memory_limit = memory_limit or int(physical / workers) or None
            threads = str(max(1, (os.cpu_count() or 1) // workers))
            cluster = distributed.LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                memory_limit=memory_limit,
                resources={"memory": memory_limit} if memory_limit else None,
                dashboard_address=":0",
                env=dict.fromkeys(
                    ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"), threads
                ),
            )
            own.callback(cluster.close)
            client = distributed.Client(cluster)
            own.callback(client.close)  # first
            quiet = logging.getLogger("distributed")
            if quiet.getEffectiveLevel() >= logging.ERROR:  # so are the local workers' logs
                client.run(quiet.setLevel, logging.ERROR)  # (on Ctrl+C: cancelled tasks)
        capacity = _memory_resource(client)
        if capacity is None:
            log(
                "the workers declare no 'memory' resource (dask worker --resources "
                "memory=BYTES): tasks are placed without memory estimates"
            )
        futures = {}
        for name, path, known in todo:
            resources = None  # a task asks for its estimated memory where workers offer it
            if capacity is not None:
                need = memory_estimate(vertex_count_hint(path), parameters)
                resources = {"memory": min(need, capacity)}
            key = f"modalviewer-mesh-{name}-{os.urandom(4).hex()}"
            future = client.submit(
                process_mesh, str(path), parameters, known, pure=False, key=key, resources=resources
            )
            futures[future] = (name, path)
        for future in distributed.as_completed(futures):
            name, path = futures.pop(future)
            try:
                result = future.result()
            except Exception as exc:  # the worker died (memory limit) or was lost
                result = {"status": "failed", "error": _one_line(exc)}
            future.release()
            take(name, path, result)


def _memory_resource(client) -> int | None:
    """The smallest ``memory`` resource of the client's workers, or None if one lacks it."""
    workers = client.scheduler_info().get("workers", {})
    amounts = [w.get("resources", {}).get("memory") for w in workers.values()]
    if not amounts or any(a is None for a in amounts):
        return None
    return int(min(amounts))
