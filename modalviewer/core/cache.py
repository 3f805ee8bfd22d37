"""On-disk cache of computed spectra, keyed by mesh hash, operator and parameters."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from .mesh import Mesh
from .spectrum import Spectrum, SpectrumFileError, load_spectrum, save_spectrum

__all__ = ["SpectrumCache", "default_cache_dir"]


def default_cache_dir() -> Path:
    """``$MODALVIEWER_CACHE`` or ``$XDG_CACHE_HOME/modalviewer`` (``~/.cache/modalviewer``)."""
    env = os.environ.get("MODALVIEWER_CACHE")
    if env:
        return Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "modalviewer"


class SpectrumCache:
    """Spectra stored as ``.npz`` files; a damaged or foreign entry is ignored and replaced."""

    def __init__(self, directory: Path | None = None):
        self.directory = Path(directory) if directory else default_cache_dir()

    def key(self, mesh: Mesh, operator: str, k: int, bending: float, membrane: float) -> str:
        params = {"op": operator, "k": int(k)}
        if operator in ("shells", "shells_normal"):
            params.update(bending=float(bending), membrane=float(membrane))
        blob = mesh.hash + json.dumps(params, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:32]

    def path(self, *args) -> Path:
        return self.directory / f"{self.key(*args)}.npz"

    def get(self, mesh, operator, k, bending=1.0, membrane=1.0) -> Spectrum | None:
        path = self.path(mesh, operator, k, bending, membrane)
        if not path.is_file():
            return None
        try:
            spec = load_spectrum(path, mesh_hash=mesh.hash)
        except (SpectrumFileError, OSError):
            try:
                path.unlink()
            except OSError:
                pass
            return None
        if (
            spec.operator != operator
            or spec.k != min(k, spec.k)
            or spec.n_vertices != mesh.n_vertices
        ):
            return None
        return spec

    def writable_path(self, mesh, operator, k, bending=1.0, membrane=1.0) -> Path:
        """Where a new entry should be written: the cache file, or a temporary file."""
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            if os.access(self.directory, os.W_OK):
                return self.path(mesh, operator, k, bending, membrane)
        except OSError:
            pass
        import tempfile

        return Path(tempfile.mkdtemp(prefix="modalviewer-")) / "spectrum.npz"

    def put(self, mesh, spec: Spectrum, k, bending=1.0, membrane=1.0) -> Path | None:
        """Store ``spec``; returns the path, or None if the cache folder is not writable."""
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            path = self.path(mesh, spec.operator, k, bending, membrane)
            save_spectrum(spec, path)
            return path
        except OSError:
            return None
