"""The spectrum cache: size limit, least-recently-used eviction, size/clear, damaged entries."""

import logging
import os
import time

import numpy as np
import pytest

from modalviewer.core.cache import DEFAULT_LIMIT_MB, SpectrumCache, default_cache_limit
from modalviewer.core.primitives import icosphere
from modalviewer.core.spectrum import Spectrum


def _spectrum(mesh, k, seed):
    rng = np.random.default_rng(seed)
    n = mesh.n_vertices
    return Spectrum(
        eigenvalues=np.sort(rng.random(k)),
        modes=rng.standard_normal((n, k)),
        operator="laplacian",
        mass=np.full(n, 1.0 / n),
        residuals=np.full(k, 1e-12),
        mesh_hash=mesh.hash,
        parameters={"k": k},
    )


@pytest.fixture(scope="module")
def mesh():
    return icosphere(2)  # 162 vertices: a 10-mode spectrum is about 14 kB


def _put(cache, mesh, k, seed=0):
    return cache.put(mesh, _spectrum(mesh, k, seed), k)


def test_limit_evicts_least_recently_used_first(tmp_path, mesh):
    probe = SpectrumCache(tmp_path / "probe")
    entry = _put(probe, mesh, 10).stat().st_size  # the size of one entry
    cache = SpectrumCache(tmp_path / "c", max_bytes=int(3.5 * entry))
    for k in (10, 11, 12):
        _put(cache, mesh, k)
    assert len(cache.entries()) == 3
    assert cache.get(mesh, "laplacian", 10) is not None  # 10 is now the most recently used
    _put(cache, mesh, 13)  # a fourth entry: over the limit, the least recently used goes
    names = [e.path for e in cache.entries()]
    assert cache.path(mesh, "laplacian", 11, 1.0, 1.0) not in names  # evicted
    for k in (10, 12, 13):
        assert cache.path(mesh, "laplacian", k, 1.0, 1.0) in names
    assert cache.size_bytes() <= cache.max_bytes
    # most recently used first: 13 (just written), then 10 (read), then 12
    order = [cache.path(mesh, "laplacian", k, 1.0, 1.0) for k in (13, 10, 12)]
    assert names == order


def test_an_entry_larger_than_the_limit_is_kept_alone(tmp_path, mesh):
    cache = SpectrumCache(tmp_path, max_bytes=1000)
    _put(cache, mesh, 10)
    p = _put(cache, mesh, 11)
    assert [e.path for e in cache.entries()] == [p]
    assert cache.get(mesh, "laplacian", 11) is not None


def test_size_and_clear(tmp_path, mesh):
    cache = SpectrumCache(tmp_path)
    sizes = [_put(cache, mesh, k).stat().st_size for k in (10, 20)]
    (tmp_path / "old.npz.abc.part").write_bytes(b"x" * 10)  # left by a killed writer
    old = time.time() - 7200
    os.utime(tmp_path / "old.npz.abc.part", (old, old))
    assert cache.size_bytes() == sum(sizes)
    assert cache.clear() == sum(sizes)
    assert cache.size_bytes() == 0 and cache.entries() == []
    assert not any(tmp_path.iterdir())
    assert cache.get(mesh, "laplacian", 10) is None


def test_zero_limit_stores_nothing(tmp_path, mesh):
    cache = SpectrumCache(tmp_path, max_bytes=0)
    assert _put(cache, mesh, 10) is None
    assert cache.size_bytes() == 0


def test_limit_from_environment(monkeypatch, tmp_path, caplog):
    monkeypatch.setenv("MODALVIEWER_CACHE_MAX_MB", "1.5")
    assert SpectrumCache(tmp_path).max_bytes == int(1.5 * 2**20)
    assert SpectrumCache(tmp_path, max_bytes=123).max_bytes == 123  # the argument wins
    monkeypatch.setenv("MODALVIEWER_CACHE_MAX_MB", "lots")
    with caplog.at_level(logging.WARNING, logger="modalviewer.cache"):
        assert default_cache_limit() == DEFAULT_LIMIT_MB * 2**20
    assert "MODALVIEWER_CACHE_MAX_MB" in caplog.text
    monkeypatch.delenv("MODALVIEWER_CACHE_MAX_MB")
    assert default_cache_limit() == 2048 * 2**20
    with pytest.raises(ValueError, match="max_bytes"):
        SpectrumCache(tmp_path, max_bytes=-1)


@pytest.mark.parametrize("damage", ["flip_bytes", "truncate", "garbage"])
def test_damaged_entry_is_dropped_with_a_warning(tmp_path, mesh, caplog, damage):
    cache = SpectrumCache(tmp_path)
    path = _put(cache, mesh, 10)
    good = _put(cache, mesh, 11)
    data = bytearray(path.read_bytes())
    if damage == "flip_bytes":  # inside the modes array: only the zip checksum sees it
        mid = len(data) // 2
        data[mid : mid + 8] = bytes(b ^ 0xFF for b in data[mid : mid + 8])
    elif damage == "truncate":
        data = data[: len(data) // 3]
    else:
        data = bytearray(b"not a spectrum at all")
    path.write_bytes(bytes(data))
    with caplog.at_level(logging.WARNING, logger="modalviewer.cache"):
        assert cache.get(mesh, "laplacian", 10) is None
    assert "damaged cache entry" in caplog.text and path.name in caplog.text
    assert not path.exists()
    assert cache.get(mesh, "laplacian", 11) is not None and good.exists()
    spec = _spectrum(mesh, 10, 0)
    again = cache.put(mesh, spec, 10)  # recomputed and stored again
    np.testing.assert_array_equal(cache.get(mesh, "laplacian", 10).modes, spec.modes)
    assert again == path


def test_spectrum_of_another_mesh_is_dropped(tmp_path, mesh):
    cache = SpectrumCache(tmp_path)
    other = icosphere(2, radius=2.0)
    path = cache.path(other, "laplacian", 10, 1.0, 1.0)
    _put(cache, mesh, 10).rename(path)  # a file under the other mesh's key
    assert cache.get(other, "laplacian", 10) is None
    assert not path.exists()


def test_spectra_of_an_older_solver_are_not_served(tmp_path, monkeypatch):
    """Spectra cached before the null-space deflation counted their zero modes by
    eigenvalue alone; the solver version in the key keeps them from being served."""
    import modalviewer as mv
    from modalviewer.core import cache as cache_module
    from modalviewer.core.primitives import icosphere

    mesh = icosphere(1)
    spec = mv.compute_spectrum(mesh, "laplacian", k=5)
    store = cache_module.SpectrumCache(tmp_path)
    monkeypatch.setattr(cache_module, "SOLVER_VERSION", cache_module.SOLVER_VERSION - 1)
    store.put(mesh, spec, 5)
    assert store.get(mesh, "laplacian", 5) is not None
    monkeypatch.undo()
    assert store.get(mesh, "laplacian", 5) is None


def test_a_cache_hit_says_it_came_from_the_cache_and_the_file_does_not(tmp_path, mesh):
    from modalviewer.core.spectrum import load_spectrum

    cache = SpectrumCache(tmp_path / "c")
    spec = _spectrum(mesh, 10, 0)
    assert not spec.from_cache
    path = cache.put(mesh, spec, 10)
    hit = cache.get(mesh, "laplacian", 10)
    assert hit.from_cache
    np.testing.assert_array_equal(hit.eigenvalues, spec.eigenvalues)
    assert not load_spectrum(path).from_cache
