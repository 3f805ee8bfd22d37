"""On-disk cache of computed spectra (:class:`SpectrumCache`), keyed by mesh hash,
operator and parameters; an entry's last use is its file's modification time.  Every
entry is checked when read; a damaged or foreign one is deleted with a warning in the
``modalviewer.cache`` log and counts as a miss."""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .mesh import Mesh
from .operators import OperatorLike, operator_info
from .spectrum import Spectrum, load_spectrum, save_spectrum

log = logging.getLogger("modalviewer.cache")

DEFAULT_LIMIT_MB = 2048  # a dozen shells spectra of mid-sized meshes, or a few large ones

_STALE_PART_SECONDS = 3600.0  # a temporary file this old belongs to a killed writer


def default_cache_limit() -> int:
    """The size limit in bytes: ``$MODALVIEWER_CACHE_MAX_MB`` megabytes (0 keeps nothing;
    not a number: a warning), else :data:`DEFAULT_LIMIT_MB`."""
    env = os.environ.get("MODALVIEWER_CACHE_MAX_MB", "").strip()
    if env:
        try:
            mb = float(env)
            if mb >= 0 and mb != float("inf"):
                return int(mb * 2**20)
        except ValueError:
            pass
        log.warning(
            "MODALVIEWER_CACHE_MAX_MB=%r is not a non-negative number of megabytes; "
            "using the default of %d MB",
            env,
            DEFAULT_LIMIT_MB,
        )
    return DEFAULT_LIMIT_MB * 2**20


@dataclass(frozen=True)
class CacheEntry:
    """One cached spectrum file: its path, size in bytes and last use (epoch seconds)."""

    path: Path
    size: int
    last_used: float


@dataclass(frozen=True)
class SolveRecord:
    """What a cached spectrum says of the solve that made it (``parameters``' seconds)."""

    operator: str
    mesh_hash: str
    n_vertices: int
    k: int
    seconds: float


SOLVER_VERSION = 2
"""Part of every cache key: raised when the solver's results change, so spectra of an
older solver are not served (2: exactly known null spaces deflated and counted)."""


class SpectrumCache:
    """Spectra as ``.npz`` files in ``directory``, at most ``max_bytes`` in all (0 stores
    nothing): beyond it the least recently used go, never the one just written or read."""

    def __init__(self, directory: Path | None = None, max_bytes: int | None = None):
        if not directory:  # $MODALVIEWER_CACHE, else $XDG_CACHE_HOME (~/.cache)/modalviewer
            directory = os.environ.get("MODALVIEWER_CACHE")
        if not directory:
            base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
            directory = Path(base) / "modalviewer"
        self.directory = Path(directory)
        if max_bytes is not None and max_bytes < 0:
            raise ValueError(f"max_bytes must be at least 0, got {max_bytes}")
        self.max_bytes = int(max_bytes) if max_bytes is not None else default_cache_limit()
        self._last_stamp = 0

    def path(
        self, mesh: Mesh, operator: OperatorLike, k: int, bending: float, membrane: float
    ) -> Path:
        """The entry's file, named by a hash of the mesh and the parameters."""
        info = operator_info(operator)
        params = {"op": info.name, "k": int(k), "solver": SOLVER_VERSION}
        if info.has_weights:
            params.update(bending=float(bending), membrane=float(membrane))
        blob = mesh.hash + json.dumps(params, sort_keys=True)
        return self.directory / f"{hashlib.sha256(blob.encode()).hexdigest()[:32]}.npz"

    def entries(self) -> list[CacheEntry]:
        """The cached spectra, most recently used first."""
        out = []
        try:
            candidates = list(self.directory.glob("*.npz"))
        except OSError:
            return []
        for p in candidates:
            try:
                st = p.stat()
            except OSError:  # deleted meanwhile
                continue
            out.append(CacheEntry(p, int(st.st_size), st.st_mtime_ns / 1e9))
        out.sort(key=lambda e: e.last_used, reverse=True)
        return out

    def size_bytes(self) -> int:
        """Total size of the cached spectra in bytes."""
        return sum(e.size for e in self.entries())

    def clear(self) -> int:
        """Delete every cached spectrum (and temporary files left by killed writers);
        returns the number of bytes freed."""
        freed = sum(e.size for e in self.entries() if self._unlink(e.path))
        try:  # and temporary files of killed writers
            parts = list(self.directory.glob("*.part"))
        except OSError:
            parts = []
        for p in parts:
            try:
                if time.time() - p.stat().st_mtime > _STALE_PART_SECONDS:
                    p.unlink()
            except OSError:
                pass
        return freed

    def solves(self) -> list[SolveRecord]:
        """The solves this machine recorded in the cache, most recently used first, read
        from each file's metadata and mass array (not its modes); entries that
        cannot be read, or carry no time (coarse-to-fine, foreign files), left out."""
        records = (_solve_record(entry.path) for entry in self.entries())
        return [record for record in records if record is not None]

    def get(self, mesh, operator, k, bending=1.0, membrane=1.0) -> Spectrum | None:
        """The cached spectrum (its ``from_cache`` set), or None.  A hit counts as a use
        (for the eviction order); an entry that cannot be read is deleted with a warning."""
        operator = operator_info(operator)
        path = self.path(mesh, operator, k, bending, membrane)
        if not path.is_file():
            return None
        try:
            spec = load_spectrum(path, mesh_hash=mesh.hash)
        except FileNotFoundError:  # evicted by another process meanwhile
            return None
        except Exception as exc:  # damaged, truncated, foreign: never a crash
            log.warning("dropped a damaged cache entry %s: %s", path.name, exc)
            self._unlink(path)
            return None
        if (
            spec.operator != operator.name
            or spec.k != min(k, spec.k)
            or spec.n_vertices != mesh.n_vertices
        ):
            log.warning("dropped a cache entry that does not match its key: %s", path.name)
            self._unlink(path)
            return None
        self._touch(path)
        self.enforce_limit(keep=path)
        spec.from_cache = True
        return spec

    def writable_path(self, mesh, operator, k, bending=1.0, membrane=1.0) -> Path:
        """Where a new entry should be written: the cache file (room made first, so that
        the limit holds once it is written), or a temporary file."""
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            if os.access(self.directory, os.W_OK) and self.max_bytes > 0:
                self.enforce_limit()
                return self.path(mesh, operator, k, bending, membrane)
        except OSError:
            pass
        return Path(tempfile.mkdtemp(prefix="modalviewer-")) / "spectrum.npz"

    def put(self, mesh, spec: Spectrum, k, bending=1.0, membrane=1.0) -> Path | None:
        """Store ``spec`` (atomically) and evict least recently used entries beyond the
        limit; returns the path, or None if nothing was stored (folder not writable, or a
        limit of 0)."""
        if self.max_bytes <= 0:
            return None
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            path = self.path(mesh, spec.operator, k, bending, membrane)
            save_spectrum(spec, path)
            self._touch(path)
        except OSError as exc:
            log.warning("could not write a cache entry in %s: %s", self.directory, exc)
            return None
        self.enforce_limit(keep=path)
        return path

    def enforce_limit(self, keep: Path | None = None) -> list[Path]:
        """Delete least recently used entries until the total is within ``max_bytes``
        (never ``keep``); returns the deleted paths."""
        entries = self.entries()
        total = sum(e.size for e in entries)
        evicted = []
        for e in reversed(entries):  # least recently used first
            if total <= self.max_bytes:
                break
            if e.path != keep and self._unlink(e.path):
                total -= e.size
                evicted.append(e.path)
        if evicted:
            log.info("cache over its limit: evicted %d least recently used", len(evicted))
        return evicted

    def _touch(self, path: Path) -> None:
        now = max(time.time_ns(), self._last_stamp + 1)  # strictly increasing here
        self._last_stamp = now
        try:
            os.utime(path, ns=(now, now))
        except OSError:
            pass

    @staticmethod
    def _unlink(path: Path) -> bool:
        try:
            path.unlink(missing_ok=True)
            return True
        except OSError:
            return False


def _solve_record(path: Path) -> SolveRecord | None:
    """The :class:`SolveRecord` of one cache file, or None."""
    try:
        with np.load(path, allow_pickle=False) as data:  # reads these two arrays only
            meta = json.loads(str(data["meta"]))
            n_vertices = len(data["mass"])
        params = meta.get("parameters", {})
        seconds = params.get("seconds_total")
        if not isinstance(seconds, (int, float)) or seconds <= 0 or "transferred_from" in params:
            return None
        return SolveRecord(
            str(meta["operator"]), str(meta.get("mesh_hash", "")), n_vertices,
            int(params["k"]), float(seconds),
        )  # fmt: skip
    except Exception:  # damaged or foreign: no record (get() deals with the file)
        return None
