"""Shape collections: the spectra, signatures and global descriptors of a whole dataset.

:func:`run_batch` computes one spectrum per mesh (and, if asked, its signatures and
descriptors) on a Dask cluster (``dask.distributed``: a local one, or an existing
scheduler), or one mesh after another in this process; :func:`open_collection` reads
the result; :meth:`Collection.similar` ranks it by spectral distance to a shape.

The store
---------
A directory::

    STORE/
      collection.json        what the store holds (format, operator, k, signatures)
      meshes/NAME.npz        one per mesh, written atomically (temporary file + rename)
      errors/NAME.json       one per mesh that failed: its source and the error
      index.json             a summary of all of them, rebuilt from the files

The access pattern decides it: many independent writers-of-one-mesh (a mesh finishes,
its file appears, whole or not at all), readers that want one mesh at a time or the
small descriptors of all.  One ``.npz`` per mesh needs nothing beyond numpy to read, a
rename makes it atomic, a killed run loses only the meshes in flight, and two meshes
never share a file (no locking, no corruption of the others).  A Zarr or HDF5 store
would add a dependency and its own crash semantics (an HDF5 file interrupted while
written can lose every group) for no gain here: meshes are read whole.  The index is a
cache: :func:`open_collection` rebuilds it from the files when they changed since it
was written (after a killed run, for example).

Each ``meshes/NAME.npz`` is also a spectrum file of :func:`~.core.spectrum.save_spectrum`
(``eigenvalues``, ``modes``, ``mass``, ``residuals``, ``meta``), so ``mv.load_spectrum``
reads it too, plus:

``entry``
    JSON: name, source path and its size and modification time, ``mesh_hash``, the
    parameters, ``key`` (SHA-256 of the geometry hash and the parameters: a second run
    skips a mesh whose key is unchanged), area, vertex count, seconds.
``shape_dna``
    the non-zero eigenvalues times the surface area (Shape-DNA: scale invariant for the
    scalar operators).
``sig.KIND.times``, ``sig.KIND.values``
    the signature of distance kind KIND (vibration, feature, hks, wks) at every vertex
    and at the standard scales (:func:`~.core.signatures.default_times`; for wks the
    energies of :func:`~.core.signatures.default_energies`), (T,) and (n, T).
``hist.KIND``
    (S, B) the signature histogram: at S of those scales, the area-weighted histogram of
    ``log10(A S_t(v) / Z(t))`` over ``B`` bins :data:`HISTOGRAM_EDGES` (``A S_t / Z`` has
    area mean 1 at every scale, so the histograms of shapes of any size compare).
``OP.eigenvalues``, ``OP.modes``, ``OP.mass``, ``OP.residuals``
    the spectrum of operator OP when a signature needs an operator other than the
    store's own.

Reading one without modalviewer::

    data = np.load("STORE/meshes/NAME.npz")
    data["eigenvalues"], data["modes"], json.loads(str(data["entry"]))
"""

from __future__ import annotations

import glob
import hashlib
import json
import logging
import os
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .core.files import atomic_write
from .core.operators import DISTANCE_KINDS, operator_for_distance, operator_info, signature_kind
from .core.spectrum import FORMAT_VERSION as SPECTRUM_FORMAT_VERSION
from .core.spectrum import Spectrum

__all__ = [
    "BatchSummary",
    "Collection",
    "CollectionError",
    "HISTOGRAM_EDGES",
    "Neighbour",
    "find_meshes",
    "mesh_names",
    "nearest_rows",
    "open_collection",
    "run_batch",
    "shape_dna_distance",
]

STORE_FORMAT = "modalviewer-collection"
STORE_VERSION = 1
HISTOGRAM_EDGES = np.linspace(-2.0, 2.0, 33)
"""Bin edges of the signature histograms, in log10 of the normalised signature."""
HISTOGRAM_SCALES = 8
"""How many of the standard scales (evenly among them) the histograms are taken at."""


class CollectionError(ValueError):
    """A store that cannot be read or written, or a mesh it does not hold."""


# ------------------------------------------------------------------ sources and names
def find_meshes(sources: Iterable[str | os.PathLike]) -> list[Path]:
    """The mesh files of ``sources``: folders (searched recursively for the extensions
    :func:`.io.load_mesh` reads, meshio's too where it is installed, less those other
    files use: :data:`.io.AMBIGUOUS_EXTENSIONS`), glob patterns, mesh files, and list
    files (any other file: one path per line, relative to the list's folder; blank
    lines and ``#`` comments skipped).
    Each file once, in the order found; ValueError for a source that matches nothing."""
    from .io import is_mesh_file

    found: list[Path] = []

    def add(path: Path) -> None:
        found.append(path)

    for source in sources:
        text = str(source)
        path = Path(text)
        if path.is_dir():
            files = [p for p in sorted(path.rglob("*")) if is_mesh_file(p, True) and p.is_file()]
            if not files:
                raise ValueError(f"{text}: no mesh files in this folder")
            for p in files:
                add(p)
        elif path.is_file() and is_mesh_file(path):
            add(path)
        elif path.is_file():
            for line in path.read_text(encoding="utf-8").splitlines():
                line = line.strip()
                if line and not line.startswith("#"):
                    entry = Path(line)
                    add(entry if entry.is_absolute() else path.parent / entry)
        elif glob.has_magic(text):
            matches = sorted(Path(p) for p in glob.glob(text, recursive=True))
            matches = [p for p in matches if p.is_file()]
            if not matches:
                raise ValueError(f"{text}: the pattern matches no file")
            for p in matches:
                add(p)
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
    return [_safe(n) for n in names]


def _safe(name: str) -> str:
    keep = "".join(c if c.isalnum() or c in "-_.+" else "_" for c in name)
    return keep.lstrip(".") or "mesh"


# ------------------------------------------------------------------ parameters and keys
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


def entry_key(mesh_hash: str, parameters: dict) -> str:
    """What identifies a stored result: the geometry and the parameters."""
    text = mesh_hash + json.dumps(parameters, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _stat(path: Path) -> list[int]:
    st = Path(path).stat()
    return [int(st.st_size), int(st.st_mtime_ns)]


# ------------------------------------------------------------------ the work of one mesh
def vertex_count_hint(path: Path) -> int:
    """A quick estimate of a mesh file's vertex count, without reading the mesh: the
    header of PLY and OFF, the ``v`` lines of OBJ, the triangle count of binary STL,
    else the file size over 40 bytes."""
    path = Path(path)
    size = path.stat().st_size
    suffix = path.suffix.lower()
    try:
        if suffix == ".ply":
            with open(path, "rb") as fh:
                for _ in range(50):
                    line = fh.readline()
                    if line.startswith(b"element vertex"):
                        return int(line.split()[2])
                    if line.strip() == b"end_header":
                        break
        elif suffix == ".off":
            with open(path, "rb") as fh:
                for line in fh:
                    words = line.split(b"#")[0].split()
                    if words and words[0].isdigit():
                        return int(words[0])
        elif suffix == ".obj":
            with open(path, "rb") as fh:
                data = fh.read()
            return data.count(b"\nv ") + data.startswith(b"v ")
        elif suffix == ".stl" and size > 84:
            return max(3, (size - 84) // 50 // 2)
    except (OSError, ValueError, IndexError):
        pass
    return max(3, size // 40)


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
    ops = [parameters["operator"]]
    for kind in parameters["signatures"]:
        op = operator_for_distance(kind)
        if op not in ops:
            ops.append(op)
    return ops


def _histogram(spec: Spectrum, area: float, kind: str = "heat") -> np.ndarray:
    """(HISTOGRAM_SCALES, bins) area-weighted histograms of log10(A S_t(v) / Z(t)), or
    for ``kind="wks"`` of log10(A W_E(v)) at energies of the default band."""
    from .core.signatures import _used, default_energies, default_times, signature, wks_sigma

    if kind == "wks":
        energies = default_energies(spec)
        picked = energies[np.linspace(0, len(energies) - 1, HISTOGRAM_SCALES).round().astype(int)]
        _, w = signature(spec, kind="wks", energies=picked, sigma=wks_sigma(energies))
        h = area * w
    else:
        mask = _used(spec, False)
        times = default_times(spec)
        picked = times[np.linspace(0, len(times) - 1, HISTOGRAM_SCALES).round().astype(int)]
        weights = np.exp(-np.outer(spec.eigenvalues[mask], picked))  # (k, S)
        s = spec.squared_modes()[:, mask] @ weights  # (n, S)
        h = area * s / weights.sum(axis=0)
    logs = np.log10(np.clip(h, 10.0 ** HISTOGRAM_EDGES[0], 10.0 ** HISTOGRAM_EDGES[-1]))
    share = spec.mass / spec.mass.sum()
    return np.stack(
        [np.histogram(logs[:, j], HISTOGRAM_EDGES, weights=share)[0] for j in range(len(picked))]
    )


def _compute(mesh, operator: str, parameters: dict) -> Spectrum:
    from .core.pipeline import compute_spectrum

    return compute_spectrum(
        mesh, operator, parameters["k"], parameters["bending"], parameters["membrane"]
    )


def shape_dna(spec: Spectrum, area: float) -> np.ndarray:
    """The non-zero eigenvalues times the area (Shape-DNA), ascending."""
    return spec.eigenvalues[~spec.zero_mode_mask()] * float(area)


def process_mesh(path: str, parameters: dict, known_key: str | None = None) -> dict:
    """The task of one mesh: read it, compute its spectra, signatures and descriptors.

    Returns ``{"status": "computed", "arrays": {...}, "entry": {...}}``, or
    ``{"status": "unchanged"}`` if the mesh's key equals ``known_key``, or
    ``{"status": "failed", "error": "..."}``: errors are results, not exceptions, so
    that one bad file does not stop the batch."""
    import warnings

    from .core.signatures import signature
    from .io import load_mesh

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
            for op in _operators(parameters):
                spectra[op] = _compute(mesh, op, parameters)
            main = spectra[parameters["operator"]]
            for op, spec in spectra.items():
                prefix = "" if op == parameters["operator"] else f"{op}."
                arrays[prefix + "eigenvalues"] = spec.eigenvalues
                arrays[prefix + "modes"] = spec.modes
                arrays[prefix + "mass"] = spec.mass
                arrays[prefix + "residuals"] = spec.residuals
                if prefix:
                    arrays[prefix + "parameters"] = np.array(json.dumps(spec.parameters))
            arrays["shape_dna"] = shape_dna(main, area)
            for kind in parameters["signatures"]:
                spec = spectra[operator_for_distance(kind)]
                times, values = signature(spec, kind=signature_kind(kind))
                arrays[f"sig.{kind}.times"] = times
                arrays[f"sig.{kind}.values"] = values
                arrays[f"hist.{kind}"] = _histogram(spec, area, signature_kind(kind))
        arrays["meta"] = np.array(
            json.dumps(
                {
                    "format": "modalviewer-spectrum",
                    "version": SPECTRUM_FORMAT_VERSION,
                    "operator": main.operator,
                    "mesh_hash": main.mesh_hash,
                    "parameters": main.parameters,
                }
            )
        )
        entry = {
            "format": STORE_FORMAT + "-entry",
            "version": STORE_VERSION,
            "source": str(Path(path).resolve()),
            "stat": _stat(Path(path)),
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


# ------------------------------------------------------------------ the store on disk
def _write_json(path: Path, value) -> None:
    def write(tmp: Path) -> None:
        tmp.write_text(json.dumps(value, indent=1, sort_keys=True), encoding="utf-8")

    atomic_write(path, write, suffix=".part")


def _write_entry(store: Path, name: str, result: dict) -> None:
    arrays = dict(result["arrays"])
    arrays["entry"] = np.array(json.dumps({**result["entry"], "name": name}))

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    atomic_write(store / "meshes" / f"{name}.npz", write, suffix=".part")
    (store / "errors" / f"{name}.json").unlink(missing_ok=True)


def _write_error(store: Path, name: str, source: Path, parameters: dict, error: str) -> None:
    try:
        stat = _stat(source)
    except OSError:
        stat = None
    _write_json(
        store / "errors" / f"{name}.json",
        {
            "name": name,
            "source": str(Path(source).resolve()),
            "stat": stat,
            "parameters": parameters,
            "error": error,
        },
    )
    # a result of the file as it was before: the store holds one record per mesh, and
    # an out-of-date result would be listed and ranked beside this failure
    (store / "meshes" / f"{name}.npz").unlink(missing_ok=True)


def _read_entry(path: Path) -> dict | None:
    """The ``entry`` record of a mesh file (only that member is read), or None if the
    file is unreadable."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return json.loads(str(data["entry"]))
    except Exception:
        return None


def _scan(store: Path) -> dict:
    """The index, from the files: entries and errors by name."""
    entries, errors = {}, {}
    for path in sorted((store / "meshes").glob("*.npz")):
        entry = _read_entry(path)
        if entry is None:
            continue
        entry.pop("parameters", None)
        entry.pop("warnings", None)
        entry["file_stat"] = _stat(path)
        entries[path.stem] = entry
    for path in sorted((store / "errors").glob("*.json")):
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        errors[path.stem] = {"source": record.get("source"), "error": record.get("error")}
    return {"format": STORE_FORMAT + "-index", "entries": entries, "errors": errors}


def rebuild_index(store: str | os.PathLike) -> dict:
    """Rebuild ``index.json`` from the files of ``store`` and write it atomically."""
    store = Path(store)
    index = _scan(store)
    _write_json(store / "index.json", index)
    return index


def _prepare_store(store: Path, parameters: dict) -> None:
    (store / "meshes").mkdir(parents=True, exist_ok=True)
    (store / "errors").mkdir(exist_ok=True)
    header = store / "collection.json"
    info = {
        "format": STORE_FORMAT,
        "version": STORE_VERSION,
        "operator": parameters["operator"],
        "k": parameters["k"],
        "bending": parameters["bending"],
        "membrane": parameters["membrane"],
        "signatures": parameters["signatures"],
    }
    if header.exists():
        try:
            old = json.loads(header.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            old = {}
        if old.get("format") != STORE_FORMAT:
            raise CollectionError(f"{store} is not a modalviewer collection")
        if old == info:
            return
        if any((store / "meshes").glob("*.npz")) or any((store / "errors").glob("*.json")):
            raise CollectionError(
                f"{store} holds {old.get('operator')} spectra, k={old.get('k')}, "
                f"signatures {','.join(old.get('signatures', [])) or 'none'}, weights "
                f"{old.get('bending')}/{old.get('membrane')}: other parameters need "
                "another store"
            )
    _write_json(header, info)


# ------------------------------------------------------------------ the batch
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

    @property
    def total(self) -> int:
        return len(self.computed) + len(self.skipped) + len(self.failed)

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


def progress_bar(stream=None) -> Callable[..., None]:
    """``bar(done, total, failed, elapsed, already=0)``: a one-line progress bar on stderr
    with the counts, the rate (of the meshes done in this run, not the ``already`` done
    before it) and the time left."""
    stream = stream or sys.stderr
    state = {"last": 0.0}

    def bar(done: int, total: int, failed: int, elapsed: float, already: int = 0) -> None:
        now = time.perf_counter()
        if done < total and now - state["last"] < 0.2:
            return
        state["last"] = now
        fraction = done / total if total else 1.0
        filled = int(30 * fraction)
        worked = done - already
        rate = worked / elapsed * 60.0 if elapsed > 0 and worked > 0 else 0.0
        left = (total - done) / (rate / 60.0) if rate > 0 else float("nan")
        left_text = "?" if left != left else _duration(left)
        note = f", {failed} failed" if failed else ""
        stream.write(
            f"\r[{'#' * filled}{'.' * (30 - filled)}] {done}/{total} meshes{note}, "
            f"{rate:.1f}/min, {left_text} left   "
        )
        if done >= total:
            stream.write("\n")
        stream.flush()

    return bar


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds // 60 % 60:02d} min"


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
    progress: Callable[..., None] | None = None,
    log: Callable[[str], None] | None = None,
) -> BatchSummary:
    """Compute every mesh of ``sources`` (see :func:`find_meshes`) into ``store``.

    Where it runs: ``client`` (a ``dask.distributed.Client``) if given; else the
    scheduler at ``scheduler`` (``"tcp://host:8786"``); else a local cluster of
    ``workers`` processes (one thread each, the cores shared among them); ``workers=0``
    runs one mesh after another in this process, without Dask.  Each mesh is one task.
    On a local cluster each worker's memory limit is ``memory_limit`` (default: the
    machine's memory over the workers) and it offers that many bytes as the resource
    ``memory``; each task asks for its :func:`memory_estimate`, so two big meshes do not
    start together on a worker that cannot hold both.  Workers of an existing scheduler
    are used the same way if they declare the resource (``dask worker ... --resources
    memory=BYTES``).

    A mesh whose stored key (geometry hash and parameters) is current is skipped, as is
    a recorded failure of the same file and parameters unless ``retry_failed``.  Each
    result is written when it arrives; a failure is recorded in ``errors/`` and the
    batch goes on.  The index is rebuilt at the end (also when interrupted).  A store
    holds one set of parameters: other ones raise CollectionError if it holds results.
    """
    store = Path(store)
    parameters = _parameters(operator, k, signatures, bending, membrane)
    paths = find_meshes(sources)
    names = mesh_names(paths)
    _prepare_store(store, parameters)
    log = log or (lambda text: None)
    summary = BatchSummary()
    start = time.perf_counter()
    todo: list[tuple[str, Path, str | None]] = []
    for name, path in zip(names, paths, strict=True):
        status, known = _done(store, name, path, parameters, retry_failed)
        if status == "done":
            summary.skipped.append(name)
            if status_failed(store, name):
                summary.failed_before.append(name)
        else:
            todo.append((name, path, known))
    total = len(paths)
    already = len(summary.skipped)

    def report() -> None:
        if progress is not None:
            elapsed = time.perf_counter() - start
            progress(summary.total, total, len(summary.failed), elapsed, already)

    def take(name: str, path: Path, result: dict) -> None:
        if result["status"] == "computed":
            _write_entry(store, name, result)
            summary.computed.append(name)
        elif result["status"] == "unchanged":
            summary.skipped.append(name)
        else:
            _write_error(store, name, path, parameters, result["error"])
            summary.failed[name] = result["error"]
        report()

    report()
    try:
        if not todo:
            pass
        elif workers == 0 and client is None and scheduler is None:
            for name, path, known in todo:
                take(name, path, process_mesh(str(path), parameters, known))
        else:
            _run_dask(todo, parameters, take, workers, scheduler, client, memory_limit, log)
    except KeyboardInterrupt:
        summary.interrupted = True
    finally:
        summary.seconds = time.perf_counter() - start
        rebuild_index(store)
    return summary


def status_failed(store: Path, name: str) -> bool:
    """Whether ``name`` is recorded as failed (and has no result)."""
    return (store / "errors" / f"{name}.json").exists() and not (
        store / "meshes" / f"{name}.npz"
    ).exists()


def _done(store: Path, name: str, path: Path, parameters: dict, retry_failed: bool):
    """("done", None) if ``name`` needs no work; else ("todo", the stored key or None)."""
    entry = _read_entry(store / "meshes" / f"{name}.npz")
    try:
        stat = _stat(path)
    except OSError:
        stat = None
    if entry is not None:
        same = entry.get("parameters") == parameters and entry.get("source") == str(path.resolve())
        if same and entry.get("stat") == stat:
            return "done", None
        return "todo", entry.get("key") if entry.get("parameters") == parameters else None
    error = store / "errors" / f"{name}.json"
    if error.exists() and not retry_failed:
        try:
            record = json.loads(error.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            record = {}
        if record.get("parameters") == parameters and record.get("stat") == stat:
            return "done", None
    return "todo", None


def _import_distributed():
    try:
        import distributed
    except ImportError:
        raise ImportError(
            "Dask is not installed: pip install 'modalviewer[batch]' (or run with --workers 0, "
            "one mesh after another in this process)"
        ) from None
    return distributed


def _run_dask(todo, parameters, take, workers, scheduler, client, memory_limit, log) -> None:
    distributed = _import_distributed()
    cluster = None
    own_client = client is None
    if client is None and scheduler is not None:
        client = distributed.Client(scheduler)
    elif client is None:
        from .viewer.model import physical_memory

        workers = max(1, int(workers))
        memory_limit = memory_limit or int(physical_memory() / workers) or None
        threads = str(max(1, (os.cpu_count() or 1) // workers))
        cluster = distributed.LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            memory_limit=memory_limit,
            resources={"memory": memory_limit} if memory_limit else None,
            dashboard_address=":0",
            env={
                name: threads
                for name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")
            },
        )
        client = distributed.Client(cluster)
        if logging.getLogger("distributed").getEffectiveLevel() >= logging.ERROR:
            client.run(_quiet_logs)  # the local workers follow this process's quiet log
    try:
        capacity = _memory_resource(client)
        if capacity is None:
            log(
                "the workers declare no 'memory' resource (dask worker --resources "
                "memory=BYTES): tasks are placed without memory estimates"
            )
        futures = {}
        for name, path, known in todo:
            extra = {}
            if capacity is not None:
                need = memory_estimate(vertex_count_hint(path), parameters)
                extra["resources"] = {"memory": min(need, capacity)}
            future = client.submit(
                process_mesh,
                str(path),
                parameters,
                known,
                pure=False,
                key=f"modalviewer-mesh-{name}-{os.urandom(4).hex()}",
                **extra,
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
    finally:
        if own_client:
            client.close()
        if cluster is not None:
            cluster.close()


def _quiet_logs() -> None:
    """Dask's log on errors only (a worker's lines on Ctrl+C: cancelled tasks)."""
    logging.getLogger("distributed").setLevel(logging.ERROR)


def _memory_resource(client) -> int | None:
    """The smallest ``memory`` resource of the client's workers, or None if one lacks it."""
    workers = client.scheduler_info().get("workers", {})
    amounts = [w.get("resources", {}).get("memory") for w in workers.values()]
    if not amounts or any(a is None for a in amounts):
        return None
    return int(min(amounts))


# ------------------------------------------------------------------ reading a store
def shape_dna_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Distance of two Shape-DNA sequences (area-normalised non-zero eigenvalues):
    ``sqrt(mean_i ((a_i - b_i) / i)^2)`` over the first ``m`` of both (m the shorter
    length), the division by the index ``i`` (1-based) making each term of the size of
    Weyl's constant, so that the high eigenvalues do not outweigh the low ones."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    m = min(len(a), len(b))
    if m == 0:
        return float("inf")
    i = np.arange(1, m + 1)
    return float(np.sqrt(np.mean(((a[:m] - b[:m]) / i) ** 2)))


class Collection:
    """A store written by :func:`run_batch`, read with numpy (see the module's text).

    ``names`` lists the stored meshes; ``spectrum(name)`` and ``signatures(name)`` read
    one; ``descriptors`` holds the small per-shape arrays of all, in the order of
    ``names``; ``errors`` the meshes that failed, with their errors.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        header = self.path / "collection.json"
        try:
            self.info = json.loads(header.read_text(encoding="utf-8"))
        except FileNotFoundError:
            raise CollectionError(f"{self.path} is not a collection (no collection.json)") from None
        except (OSError, ValueError) as exc:
            raise CollectionError(f"{header} is unreadable ({exc})") from None
        if self.info.get("format") != STORE_FORMAT:
            raise CollectionError(f"{self.path} is not a modalviewer collection")
        self.index = self._index()
        self._descriptors = None

    def _index(self) -> dict:
        """The index file if it matches the files, else one rebuilt from them (written
        back if the store is writable)."""
        try:
            index = json.loads((self.path / "index.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            index = None
        if index is not None and self._current(index):
            return index
        try:
            return rebuild_index(self.path)
        except OSError:
            return _scan(self.path)

    def _current(self, index: dict) -> bool:
        files = {p.stem: p for p in (self.path / "meshes").glob("*.npz")}
        entries = index.get("entries", {})
        if set(files) != set(entries):
            return False
        errors = {p.stem for p in (self.path / "errors").glob("*.json")}
        if errors != set(index.get("errors", {})):
            return False
        return all(_stat(files[n]) == entries[n].get("file_stat") for n in files)

    def __repr__(self) -> str:
        return (
            f"Collection({str(self.path)!r}, {len(self.names)} meshes, "
            f"{len(self.errors)} errors, operator={self.operator!r}, k={self.k})"
        )

    def __len__(self) -> int:
        return len(self.names)

    def __contains__(self, name) -> bool:
        return name in self.index["entries"]

    @property
    def operator(self) -> str:
        return self.info["operator"]

    @property
    def k(self) -> int:
        return int(self.info["k"])

    @property
    def names(self) -> list[str]:
        """The stored meshes' names, sorted."""
        return sorted(self.index["entries"])

    @property
    def errors(self) -> dict[str, str]:
        """Name -> error of every mesh that failed."""
        return {name: e["error"] for name, e in sorted(self.index["errors"].items())}

    def entry(self, name: str) -> dict:
        """The stored record of ``name``: source, mesh_hash, area, n_vertices, ..."""
        try:
            return self.index["entries"][name]
        except KeyError:
            raise CollectionError(f"{self.path} holds no mesh {name!r}") from None

    def source(self, name: str) -> Path:
        """The mesh file ``name`` was computed from."""
        return Path(self.entry(name)["source"])

    def file(self, name: str) -> Path:
        self.entry(name)
        return self.path / "meshes" / f"{name}.npz"

    def spectrum(self, name: str, operator: str | None = None) -> Spectrum:
        """The spectrum of ``name`` (of ``operator``, if a signature needed a second)."""
        from .core.spectrum import load_spectrum

        path = self.file(name)
        operator = operator or self.operator
        if operator == self.operator:
            return load_spectrum(path)
        with np.load(path, allow_pickle=False) as data:
            if f"{operator}.eigenvalues" not in data:
                raise CollectionError(f"{name} has no {operator} spectrum")
            return Spectrum(
                eigenvalues=np.array(data[f"{operator}.eigenvalues"]),
                modes=np.array(data[f"{operator}.modes"]),
                operator=operator,
                mass=np.array(data[f"{operator}.mass"]),
                residuals=np.array(data[f"{operator}.residuals"]),
                mesh_hash=self.entry(name)["mesh_hash"],
                parameters=json.loads(str(data[f"{operator}.parameters"])),
            )

    def signatures(self, name: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Kind -> (times (T,), values (n, T)) of ``name``'s stored signatures."""
        out = {}
        with np.load(self.file(name), allow_pickle=False) as data:
            for key in data.files:
                if key.startswith("sig.") and key.endswith(".times"):
                    kind = key[4:-6]
                    out[kind] = (np.array(data[key]), np.array(data[f"sig.{kind}.values"]))
        return out

    @property
    def descriptors(self) -> dict[str, np.ndarray]:
        """The global descriptors of all meshes, rows in the order of :attr:`names`:
        ``shape_dna`` (N, m) (area-normalised non-zero eigenvalues, NaN past a shape's
        own count), ``area`` (N,), ``n_vertices`` (N,), and per stored signature kind
        ``histogram.KIND`` (N, S, B) (bins :data:`HISTOGRAM_EDGES`)."""
        if self._descriptors is None:
            self._descriptors = self._read_descriptors()
        return self._descriptors

    def _read_descriptors(self) -> dict[str, np.ndarray]:
        names = self.names
        dna, hists = [], {}
        for row, name in enumerate(names):
            with np.load(self.file(name), allow_pickle=False) as data:
                dna.append(np.array(data["shape_dna"]))
                for key in data.files:
                    if key.startswith("hist."):
                        hists.setdefault(key[5:], {})[row] = np.array(data[key])
        width = max((len(d) for d in dna), default=0)
        table = np.full((len(names), width), np.nan)
        for row, d in enumerate(dna):
            table[row, : len(d)] = d
        out = {
            "shape_dna": table,
            "area": np.array([self.entry(n)["area"] for n in names], dtype=float),
            "n_vertices": np.array([self.entry(n)["n_vertices"] for n in names], dtype=int),
        }
        for kind, rows in hists.items():
            shape = next(iter(rows.values())).shape
            stack = np.full((len(names), *shape), np.nan)
            for row, h in rows.items():
                stack[row] = h
            out[f"histogram.{kind}"] = stack
        return out

    def name_of(self, mesh_hash: str) -> str | None:
        """The stored mesh with this geometry hash, or None."""
        for name in self.names:
            if self.entry(name).get("mesh_hash") == mesh_hash:
                return name
        return None

    def query_dna(self, mesh=None, spectrum: Spectrum | None = None) -> tuple[np.ndarray, str]:
        """(Shape-DNA, mesh hash) of ``mesh`` (a :class:`~.core.mesh.Mesh`): the stored one
        if the store holds its geometry, else from ``spectrum`` (of the store's operator
        with at least its k modes) or a spectrum computed with the store's parameters."""
        name = self.name_of(mesh.hash)
        if name is not None:
            row = self.names.index(name)
            return self.descriptors["shape_dna"][row], mesh.hash
        if not self.spectrum_fits(spectrum):
            from .core.pipeline import compute_spectrum

            spectrum = compute_spectrum(
                mesh, self.operator, self.k, self.info["bending"], self.info["membrane"]
            )
        else:
            spectrum = _first_modes(spectrum, self.k)
        return shape_dna(spectrum, mesh.total_area), mesh.hash

    def spectrum_fits(self, spectrum: Spectrum | None) -> bool:
        """Whether ``spectrum`` can stand for the store's: its operator and weights, at
        least its k modes."""
        if spectrum is None or spectrum.operator != self.operator:
            return False
        if spectrum.k < min(
            self.k, spectrum.n_vertices * operator_info(self.operator).unknowns_per_vertex
        ):
            return False
        if operator_info(self.operator).has_weights:
            for weight in ("bending", "membrane"):
                if float(spectrum.parameters.get(weight, 1.0)) != float(self.info[weight]):
                    return False
        return True

    def needs_spectrum(self, mesh, spectrum: Spectrum | None = None) -> bool:
        """Whether ranking by ``mesh`` must compute its spectrum first: the store does not
        hold its geometry and ``spectrum`` does not fit (:meth:`spectrum_fits`)."""
        return self.name_of(mesh.hash) is None and not self.spectrum_fits(spectrum)

    def similar(self, query, n: int | None = 10, spectrum: Spectrum | None = None):
        """The stored meshes nearest to ``query`` by Shape-DNA distance
        (:func:`shape_dna_distance`), nearest first, as [(name, distance)], at most ``n``
        (all with None).  ``query`` is a stored name, a mesh file or a
        :class:`~.core.mesh.Mesh`; a stored mesh of the same geometry comes first (at
        distance 0), before shapes at a distance 0 by rounding."""
        from .core.mesh import Mesh

        if isinstance(query, str) and query in self:
            dna = self.descriptors["shape_dna"][self.names.index(query)]
            own = self.entry(query)["mesh_hash"]
        else:
            if not isinstance(query, Mesh):
                from .io import load_mesh

                query = load_mesh(query)
            dna, own = self.query_dna(query, spectrum)
        table = self.descriptors["shape_dna"]
        ranked = []
        for row, name in enumerate(self.names):
            same = self.entry(name).get("mesh_hash") == own
            d = 0.0 if same else shape_dna_distance(dna, table[row])
            ranked.append((not same, d, name))
        ranked.sort()
        ranked = [(name, d) for _, d, name in ranked]
        return ranked if n is None else ranked[: max(0, int(n))]


def _first_modes(spec: Spectrum, k: int) -> Spectrum:
    return Spectrum(
        eigenvalues=spec.eigenvalues[:k],
        modes=spec.modes[..., :k],
        operator=spec.operator,
        mass=spec.mass,
        residuals=spec.residuals[:k],
        mesh_hash=spec.mesh_hash,
        parameters=spec.parameters,
    )


def open_collection(path: str | os.PathLike) -> Collection:
    """The collection at ``path`` (a store of :func:`run_batch`), CollectionError if it is
    none.  Needs numpy only.

    Parameters
    ----------
    path : str or os.PathLike
        The store's folder, as ``modalviewer batch -o`` wrote it.

    Returns
    -------
    Collection
        ``names``, ``spectrum(name)``, ``signatures(name)``, ``descriptors``, ``errors``,
        ``similar(...)``.

    Raises
    ------
    CollectionError
        If ``path`` is not a collection.
    """
    return Collection(path)


@dataclass(frozen=True)
class Neighbour:
    """One row of :func:`nearest_rows`: a stored mesh, its distance to the query (None
    without one), its source file and whether that file is there to open."""

    name: str
    distance: float | None
    source: Path
    available: bool

    @property
    def label(self) -> str:
        """The row in words: name, distance, and "(file missing)" if it cannot open."""
        words = self.name if self.distance is None else f"{self.name}  ({self.distance:.4g})"
        return words if self.available else f"{words}  (file missing: {self.source})"


def nearest_rows(collection: Collection, mesh=None, spectrum=None, n=None) -> list[Neighbour]:
    """The rows a list of the collection shows: nearest to ``mesh`` first (a
    :class:`~.core.mesh.Mesh`, with its ``spectrum`` if one of the store's operator is at
    hand; see :meth:`Collection.similar`), or every mesh by name without a mesh."""
    if mesh is None:
        ranked = [(name, None) for name in collection.names]
    else:
        ranked = collection.similar(mesh, n=n, spectrum=spectrum)
    rows = []
    for name, distance in ranked:
        source = collection.source(name)
        rows.append(Neighbour(name, distance, source, source.is_file()))
    return rows
