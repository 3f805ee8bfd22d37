"""Distances between two meshes (core.cross) and ``modalviewer distance A --to B``."""

import importlib.util
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh

import modalviewer as mv

ROOT = Path(__file__).resolve().parents[2]


def _moved(mesh: mv.Mesh, seed: int = 1, scale: float = 1.0) -> mv.Mesh:
    """``mesh`` rotated, translated and scaled by ``scale`` (same vertex numbering)."""
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return mv.Mesh(scale * mesh.vertices @ q.T + [0.3, -2.0, 5.0], mesh.faces)


@pytest.fixture(scope="module")
def spot_pair(spot):
    return spot, _moved(spot)


@pytest.mark.parametrize("operator", ["laplacian", "modified_dirichlet", "shells"])
def test_rigid_motion_gives_identical_distances(spot_pair, operator):
    a, b = spot_pair
    sa, sb = mv.compute_spectrum(a, operator, k=20), mv.compute_spectrum(b, operator, k=20)
    np.testing.assert_allclose(mv.common_times(sa, sb), mv.default_times(sa), rtol=1e-9)
    for v in (0, 1234, 2900):
        same = mv.multiscale_distance(sa, v)
        cross = mv.cross_distance(sa, v, sb)
        # measured: 5e-14 (Laplacian) and 1.4e-10 (shells) of the largest distance
        np.testing.assert_allclose(cross, same, rtol=0, atol=1e-8 * same.max())
        w, dist = mv.best_match(sa, v, sb)
        assert w == v and dist <= 1e-8 * same.max()
    matches = mv.mutual_best_matches(sa, [5, 100, 2000], sb)
    assert matches.matches_b.tolist() == [5, 100, 2000]
    assert matches.back_matches_a.tolist() == [5, 100, 2000] and matches.mutual.all()


@pytest.fixture(scope="module")
def spot_two_resolutions(spot):
    """spot and spot with every triangle split in four (same surface, 4x the vertices)."""
    v, f = trimesh.remesh.subdivide(np.array(spot.vertices), np.array(spot.faces))
    fine = mv.Mesh(v, f)
    return (
        mv.compute_spectrum(spot, "laplacian", k=40),
        mv.compute_spectrum(fine, "laplacian", k=40),
        fine,
    )


def test_two_resolutions_heat_kernel_finds_the_same_point(spot, spot_two_resolutions):
    sa, sb, fine = spot_two_resolutions
    assert fine.n_vertices == 11714
    # the midpoint split keeps spot's vertices first, at the same positions
    np.testing.assert_array_equal(fine.vertices[: spot.n_vertices], spot.vertices)
    tables = mv.CrossTables(sa, sb)
    picks = np.random.default_rng(0).choice(spot.n_vertices, 200, replace=False)
    ranks = np.array([mv.distance_ranks(tables.a_to_b(v), [v])[0] for v in picks])
    # among the best 1 % of the fine mesh's vertices (measured: at most 20, median 1)
    assert ranks.max() <= 0.01 * fine.n_vertices
    assert np.median(ranks) <= 3
    # the other way round: from the fine mesh's copy of each vertex back to spot
    back = np.array([mv.distance_ranks(tables.b_to_a(v), [v])[0] for v in picks[:50]])
    assert back.max() <= 0.01 * spot.n_vertices


def test_distance_between_meshes_is_symmetric(spot_two_resolutions):
    sa, sb, _ = spot_two_resolutions
    d_ab = mv.cross_distance(sa, 77, sb)
    for w in (0, 5000, 11713):
        d_ba = mv.cross_distance(sb, w, sa)
        assert d_ba[77] == pytest.approx(d_ab[w], rel=1e-12)
    # the one-row path of cross_distance agrees with the tables of both meshes
    np.testing.assert_allclose(mv.CrossTables(sa, sb).a_to_b(77), d_ab, rtol=0, atol=1e-12)


def _make_assets():
    spec = importlib.util.spec_from_file_location("make_assets", ROOT / "scripts/make_assets.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_two_resolutions_of_the_hand_match_every_fingertip():
    """Two iso-surfaces of the same implicit hand: no vertex lies on the other mesh."""
    pytest.importorskip("pyvista")
    make_assets = _make_assets()
    (a, tips_a), (b, tips_b) = make_assets.hand(False, 0.09), make_assets.hand(False, 0.06)
    assert (a.n_vertices, b.n_vertices) == (2521, 5694)
    sa, sb = mv.compute_spectrum(a, "laplacian", k=40), mv.compute_spectrum(b, "laplacian", k=40)
    names = sorted(tips_a)
    va = [int(np.argmin(np.linalg.norm(a.vertices - tips_a[k], axis=1))) for k in names]
    vb = [int(np.argmin(np.linalg.norm(b.vertices - tips_b[k], axis=1))) for k in names]
    tables = mv.CrossTables(sa, sb)
    for v, w in zip(va, vb, strict=True):
        # measured: every tip's counterpart is the nearest of all 5694 vertices
        assert mv.distance_ranks(tables.a_to_b(v), [w])[0] <= 0.01 * b.n_vertices
    matches = tables.mutual_best_matches(va, vb)
    assert matches.matches_b.tolist() == vb and matches.mutual.all()


def test_scale(spot):
    """The Laplacian spectrum scales with the area, the shells spectrum does not."""
    big = _moved(spot, scale=3.0)
    sa, sb = (
        mv.compute_spectrum(spot, "laplacian", k=20),
        mv.compute_spectrum(big, "laplacian", k=20),
    )
    np.testing.assert_allclose(sb.eigenvalues[1:], sa.eigenvalues[1:] / 9, rtol=1e-9)
    # each normalised signature carries 1 / area: the one-mesh distance shrinks by 9
    np.testing.assert_allclose(
        mv.multiscale_distance(sb, 10), mv.multiscale_distance(sa, 10) / 9, rtol=1e-7, atol=1e-12
    )
    with pytest.warns(mv.ScaleWarning, match="rescale"):
        mv.cross_distance(sa, 10, sb)
    huge = mv.compute_spectrum(_moved(spot, scale=30.0), "laplacian", k=20)
    with pytest.warns(mv.ScaleWarning), pytest.raises(ValueError, match="do not overlap"):
        mv.cross_distance(sa, 10, huge)
    # both rescaled to the same area: the scaled copy is the same shape again
    one, big_one = mv.rescale_to_area(spot, 2.0), mv.rescale_to_area(big, 2.0)
    assert big_one.total_area == pytest.approx(2.0, rel=1e-12)
    s1, s2 = (
        mv.compute_spectrum(one, "laplacian", k=20),
        mv.compute_spectrum(big_one, "laplacian", k=20),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", mv.ScaleWarning)
        d = mv.cross_distance(s1, 10, s2)
    same = mv.multiscale_distance(s1, 10)
    np.testing.assert_allclose(d, same, rtol=0, atol=1e-8 * same.max())
    # shells: eigenvalue ratios of the 3x copy are not one common factor
    h1, h3 = mv.compute_spectrum(spot, "shells", k=20), mv.compute_spectrum(big, "shells", k=20)
    # (at rest the bending part of the Hessian over the mass scales like s^-4, stretching
    # like s^-3, area like s^-2; measured ratios 0.0203 .. 0.0274, spread 1.35)
    ratio = h3.eigenvalues[6:] / h1.eigenvalues[6:]
    assert np.all((ratio > 1 / 81) & (ratio < 1 / 27))
    assert ratio.max() / ratio.min() > 1.2


def test_bad_input(spot_pair):
    a, b = spot_pair
    sa, sb = mv.compute_spectrum(a, "laplacian", k=10), mv.compute_spectrum(b, "shells", k=10)
    with pytest.raises(ValueError, match="same operator"):
        mv.cross_distance(sa, 0, sb)
    with pytest.raises(IndexError, match="out of range"):
        mv.cross_distance(sa, a.n_vertices, sa)
    with pytest.raises(ValueError, match="non-empty"):
        mv.mutual_best_matches(sa, [], sa)
    with pytest.raises(ValueError, match="0 < t1 < t2"):
        mv.cross_distance(sa, 0, sa, t_range=(2.0, 1.0))
    with pytest.raises(ValueError, match="positive"):
        mv.rescale_to_area(a, -1.0)


def _write_obj(path: Path, mesh: mv.Mesh) -> Path:
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in mesh.vertices.tolist()]
    lines += [f"f {i + 1} {j + 1} {k + 1}" for i, j, k in mesh.faces.tolist()]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_cli_distance_to_a_second_mesh(tmp_path, spot, monkeypatch):
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    a = _write_obj(tmp_path / "a.obj", spot)
    b = _write_obj(tmp_path / "b.obj", _moved(spot, scale=1.2))
    csv, png = tmp_path / "d.csv", tmp_path / "d.png"
    args = ["distance", a, "--vertex", 100, "--to", b, "--kind", "hks", "-k", 20]
    run = [sys.executable, "-m", "modalviewer", *map(str, args)]
    out = [*run, "--csv", csv, "-o", png, "--size", "400x200"]
    r = subprocess.run(list(map(str, out)), capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "modalviewer: warning: the meshes' areas differ" in r.stderr  # 1.44 x the area
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert rows.shape == (spot.n_vertices, 2)
    sa = mv.compute_spectrum(spot, "laplacian", k=20)
    sb = mv.compute_spectrum(_moved(spot, scale=1.2), "laplacian", k=20)
    with pytest.warns(mv.ScaleWarning):
        expected = mv.cross_distance(sa, 100, sb)
    np.testing.assert_allclose(rows[:, 1], expected, rtol=1e-8, atol=1e-10 * expected.max())
    # at 1.44 x the area the best match is another vertex (measured: 584, not 100)
    assert f"best match {int(np.argmin(expected))} " in r.stdout
    from PIL import Image

    image = np.asarray(Image.open(png).convert("RGB"))
    assert image.shape[1] == 400 and image.shape[0] > 200  # two panels and their captions
    right = image[:, 200:].reshape(-1, 3).astype(int)
    assert np.sum((right[:, 0] > 150) & (right[:, 1] < 100)) > 500  # red: far vertices
    assert len(list((tmp_path / "cache").glob("*.npz"))) == 2  # both spectra kept
    # both rescaled to unit area: the copy's own vertex, a mutual best match, no warning
    r = subprocess.run(list(map(str, [*run, "--rescale"])), capture_output=True, text=True)
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr
    assert "best match 100 " in r.stdout and "), mutual;" in r.stdout
    bad = [*run[:-6], "--to", tmp_path / "missing.obj"]
    r = subprocess.run(list(map(str, bad)), capture_output=True, text=True)
    assert r.returncode == 1 and r.stderr.count("\n") == 1, r.stderr
    assert r.stderr.startswith("modalviewer: error:") and "Traceback" not in r.stderr
