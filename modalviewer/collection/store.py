"""The store of a shape collection: its files, and :class:`Collection` reading them and
ranking them by spectral distance to a shape (:meth:`Collection.similar`).

A folder of ``collection.json``, ``meshes/NAME.npz`` per mesh (a spectrum file with the
entry, Shape-DNA, signatures and histograms), ``errors/NAME.json`` per failure and
``index.json`` rebuilt from those; one file per mesh, so that workers finish
independently, a killed run loses only what was in flight and numpy alone reads it.  The
arrays are listed in the library guide (docs/library-guide.md, "Shape collections").
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..core.files import atomic_write
from ..core.spectrum import SPECTRUM_ARRAYS, Spectrum

STORE_FORMAT = "modalviewer-collection"
STORE_VERSION = 1
HISTOGRAM_EDGES = np.linspace(-2.0, 2.0, 33)
"""Bin edges of the signature histograms, in log10 of the normalised signature."""
HISTOGRAM_SCALES = 8
"""How many of the standard scales (evenly among them) the histograms are taken at."""


class CollectionError(ValueError):
    """A store that cannot be read or written, or a mesh it does not hold."""


def entry_key(mesh_hash: str, parameters: dict) -> str:
    """What identifies a stored result: the geometry and the parameters."""
    text = mesh_hash + json.dumps(parameters, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def file_stat(path: Path) -> list[int] | None:
    """[size, modification time in ns] of a file, None if it cannot be read."""
    try:
        st = Path(path).stat()
    except OSError:
        return None
    return [int(st.st_size), int(st.st_mtime_ns)]


def read_json(path: Path) -> dict | None:
    """The JSON object of a file, None if it is missing or unreadable."""
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def shape_dna(spec: Spectrum, area: float) -> np.ndarray:
    """The non-zero eigenvalues times the area (Shape-DNA), ascending."""
    return spec.eigenvalues[~spec.zero_mode_mask()] * float(area)


def _write_json(path: Path, value) -> None:
    def write(tmp: Path) -> None:
        tmp.write_text(json.dumps(value, indent=1, sort_keys=True), encoding="utf-8")

    atomic_write(path, write, suffix=".part")


def write_entry(store: Path, name: str, result: dict) -> None:
    arrays = dict(result["arrays"])
    arrays["entry"] = np.array(json.dumps({**result["entry"], "name": name}))

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    atomic_write(store / "meshes" / f"{name}.npz", write, suffix=".part")
    (store / "errors" / f"{name}.json").unlink(missing_ok=True)


def write_error(store: Path, name: str, source: Path, parameters: dict, error: str) -> None:
    _write_json(
        store / "errors" / f"{name}.json",
        {
            "name": name,
            "source": str(Path(source).resolve()),
            "stat": file_stat(source),
            "parameters": parameters,
            "error": error,
        },
    )
    # a result of the file as it was before: the store holds one record per mesh, and
    # an out-of-date result would be listed and ranked beside this failure
    (store / "meshes" / f"{name}.npz").unlink(missing_ok=True)


def read_entry(path: Path) -> dict | None:
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
        entry = read_entry(path)
        if entry is None:
            continue
        entry.pop("parameters", None)
        entry.pop("warnings", None)
        entry["file_stat"] = file_stat(path)
        entries[path.stem] = entry
    for path in sorted((store / "errors").glob("*.json")):
        record = read_json(path)
        if record is None:
            continue
        errors[path.stem] = {"source": record.get("source"), "error": record.get("error")}
    return {"format": STORE_FORMAT + "-index", "entries": entries, "errors": errors}


def rebuild_index(store: str | os.PathLike) -> dict:
    """Rebuild ``index.json`` from the files of ``store`` and write it atomically."""
    store = Path(store)
    index = _scan(store)
    _write_json(store / "index.json", index)
    return index


def prepare_store(store: Path, parameters: dict) -> None:
    (store / "meshes").mkdir(parents=True, exist_ok=True)
    (store / "errors").mkdir(exist_ok=True)
    header = store / "collection.json"
    info = {"format": STORE_FORMAT, "version": STORE_VERSION}  # one set of parameters
    info |= {key: parameters[key] for key in ("operator", "k", "bending", "membrane", "signatures")}
    if header.exists():
        old = read_json(header) or {}
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
    """A store written by :func:`run_batch` (its files: the module docstring), read with
    numpy alone."""

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
        index = read_json(self.path / "index.json")
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
        return all(file_stat(files[n]) == entries[n].get("file_stat") for n in files)

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
        from ..core.spectrum import load_spectrum

        path = self.file(name)
        operator = operator or self.operator
        if operator == self.operator:
            return load_spectrum(path)
        with np.load(path, allow_pickle=False) as data:
            if f"{operator}.eigenvalues" not in data:
                raise CollectionError(f"{name} has no {operator} spectrum")
            return Spectrum(
                **{part: np.array(data[f"{operator}.{part}"]) for part in SPECTRUM_ARRAYS},
                operator=operator,
                mesh_hash=self.entry(name)["mesh_hash"],
                parameters=json.loads(str(data[f"{operator}.parameters"])),
            )

    def signatures(self, name: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Kind -> (times (T,), values (n, T)) of ``name``'s stored signatures."""
        with np.load(self.file(name), allow_pickle=False) as data:
            return {
                kind: (np.array(data[f"sig.{kind}.times"]), np.array(data[f"sig.{kind}.values"]))
                for kind in self.info.get("signatures", [])  # the store's, of every mesh
            }

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
        names, kinds = self.names, self.info.get("signatures", [])
        dna, hists = [], {kind: [] for kind in kinds}  # a store's meshes share its kinds
        for name in names:
            with np.load(self.file(name), allow_pickle=False) as data:
                dna.append(np.array(data["shape_dna"]))
                for kind in kinds:
                    hists[kind].append(np.array(data[f"hist.{kind}"]))
        width = max((len(d) for d in dna), default=0)
        out = {
            "shape_dna": np.array(
                [np.pad(d, (0, width - len(d)), constant_values=np.nan) for d in dna]
            ).reshape(len(names), width),
            "area": np.array([self.entry(n)["area"] for n in names], dtype=float),
            "n_vertices": np.array([self.entry(n)["n_vertices"] for n in names], dtype=int),
        }
        bins = (len(names), HISTOGRAM_SCALES, len(HISTOGRAM_EDGES) - 1)
        out.update(
            (f"histogram.{kind}", np.array(rows).reshape(bins)) for kind, rows in hists.items()
        )
        return out

    def name_of(self, mesh_hash: str) -> str | None:
        """The stored mesh with this geometry hash, or None."""
        return next((n for n in self.names if self.entry(n).get("mesh_hash") == mesh_hash), None)

    def spectrum_fits(self, spectrum: Spectrum | None) -> bool:
        """Whether ``spectrum`` can stand for the store's: its operator and weights, at
        least its k modes."""
        if spectrum is None or spectrum.operator != self.operator:
            return False
        info = spectrum.operator_info
        if spectrum.k < min(self.k, spectrum.n_vertices * info.unknowns_per_vertex):
            return False
        if info.has_weights:
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
        distance 0), before shapes at a distance 0 by rounding.  A mesh the store does not
        hold is ranked by ``spectrum`` where it fits (:meth:`spectrum_fits`), else by a
        spectrum computed with the store's parameters."""
        from ..interop import as_mesh

        table = self.descriptors["shape_dna"]
        if isinstance(query, str) and query in self:
            stored = query
        else:
            query = as_mesh(query)
            stored = self.name_of(query.hash)
        if stored is not None:
            dna, own = table[self.names.index(stored)], self.entry(stored)["mesh_hash"]
        else:
            if not self.spectrum_fits(spectrum):
                from ..core.pipeline import compute_spectrum

                weights = self.info["bending"], self.info["membrane"]
                spectrum = compute_spectrum(query, self.operator, self.k, *weights)
            # its first k eigenvalues, as the store's spectra hold them
            spectrum = replace(spectrum, eigenvalues=spectrum.eigenvalues[: self.k])
            dna, own = shape_dna(spectrum, query.total_area), query.hash
        ranked = []
        for row, name in enumerate(self.names):
            same = self.entry(name).get("mesh_hash") == own
            d = 0.0 if same else shape_dna_distance(dna, table[row])
            ranked.append((not same, d, name))
        ranked.sort()
        ranked = [(name, d) for _, d, name in ranked]
        return ranked if n is None else ranked[: max(0, int(n))]


def open_collection(path: str | os.PathLike) -> Collection:
    """The :class:`Collection` in the folder ``path`` (``modalviewer batch -o`` wrote
    it; numpy alone reads it); :class:`CollectionError` if it is none."""
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
