"""Atomic writes keep the permissions of the user's umask (mkstemp alone gives 0600)."""

import os

import pytest

from modalviewer.core.files import atomic_write, current_umask


@pytest.mark.parametrize("umask", [0o022, 0o077, 0o002])
def test_atomic_write_uses_the_umask(tmp_path, umask):
    old = os.umask(umask)
    try:
        assert current_umask() == umask
        path = atomic_write(tmp_path / "a.txt", lambda tmp: tmp.write_text("x"))
        plain = tmp_path / "plain.txt"
        plain.write_text("x")  # what open() gives, for comparison
    finally:
        os.umask(old)
    assert path.read_text() == "x"
    assert path.stat().st_mode & 0o777 == plain.stat().st_mode & 0o777 == 0o666 & ~umask


def test_failed_write_leaves_nothing(tmp_path):
    target = tmp_path / "b.txt"
    target.write_text("old")

    def fail(tmp):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(target, fail)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.txt"]


def test_saved_spectrum_gets_the_umask_permissions(tmp_path):
    import modalviewer as mv
    from modalviewer.core.primitives import icosphere

    spec = mv.compute_spectrum(icosphere(1), "laplacian", k=4)
    old = os.umask(0o022)
    try:
        mv.save_spectrum(spec, tmp_path / "s.npz")
    finally:
        os.umask(old)
    assert (tmp_path / "s.npz").stat().st_mode & 0o777 == 0o644
    again = mv.load_spectrum(tmp_path / "s.npz")
    assert again.eigenvalues.tolist() == spec.eigenvalues.tolist()
