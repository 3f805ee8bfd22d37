"""The paper's claims, measured on the shipped demo meshes (assets/, scripts/make_assets.py).

Numbers measured when written are in the comments; the assertions leave a margin.
"""

import json
from pathlib import Path

import numpy as np

import modalviewer as mv
from modalviewer.core.shells import dihedral_angles, hinges
from scripts import make_assets

ASSETS = Path(__file__).resolve().parents[1] / "assets"


def fold_vertices() -> np.ndarray:
    """Indices of the demo plate's vertices on the fold line."""
    return np.flatnonzero(np.abs(make_assets.plate().vertices[:, 0] - make_assets.FOLD_X) < 1e-12)


def sharp_vertices(mesh, angle_degrees: float = 30.0) -> np.ndarray:
    """(n,) True at vertices on an edge whose dihedral angle exceeds ``angle_degrees``."""
    h = hinges(mesh)
    theta = np.abs(dihedral_angles(mesh.vertices, h))
    sharp = np.zeros(mesh.n_vertices, dtype=bool)
    sharp[h[theta > np.radians(angle_degrees)][:, :2].ravel()] = True
    return sharp


def _energy_share(spec, vertices, modes):
    """Share of each mode's Mass-weighted squared amplitude that sits on ``vertices``."""
    m = spec.mass
    phi2 = spec.squared_modes()[:, modes]
    return (m[vertices, None] * phi2[vertices]).sum(axis=0) / (m[:, None] * phi2).sum(axis=0)


def test_fig1_plate_and_isometric_fold():
    plate = mv.load_mesh(ASSETS / "demo_plate.obj")
    folded = mv.load_mesh(ASSETS / "demo_folded_plate.obj")
    lap_plate = mv.compute_spectrum(plate, "laplacian", k=20)
    mod_plate = mv.compute_spectrum(plate, "modified_dirichlet", k=20)
    lap_fold = mv.compute_spectrum(folded, "laplacian", k=20)
    mod_fold = mv.compute_spectrum(folded, "modified_dirichlet", k=20)
    scale = lap_plate.eigenvalues.max()
    # flat plate: E_D^N spectrum == Laplacian spectrum (measured difference 0.0)
    np.testing.assert_allclose(mod_plate.eigenvalues, lap_plate.eigenvalues, atol=1e-12 * scale)
    # isometric fold: Laplacian spectrum unchanged (measured 3.6e-15 relative)
    np.testing.assert_allclose(lap_fold.eigenvalues, lap_plate.eigenvalues, atol=1e-10 * scale)
    # low E_D^N modes nearly vanish on the fold: share of mode energy on the fold line's
    # vertices (2.1 % of the area) measured <= 0.28 % for E_D^N modes 0-5, up to 4.2 % for
    # the Laplacian modes 1-6
    fold = fold_vertices()
    area_share = mod_fold.mass[fold].sum() / mod_fold.mass.sum()
    mod_share = _energy_share(mod_fold, fold, range(6))
    lap_share = _energy_share(lap_fold, fold, range(1, 7))
    assert mod_share.max() < 0.2 * area_share
    assert lap_share.max() > 1.5 * area_share
    # and the E_D^N spectrum does change
    assert np.max(np.abs(mod_fold.eigenvalues - mod_plate.eigenvalues)) > 1e-3 * scale


def test_fig3_modified_dirichlet_modes_avoid_sharp_edges():
    torus = mv.load_mesh(ASSETS / "demo_double_torus.obj")
    sharp = np.flatnonzero(sharp_vertices(torus))
    lap = mv.compute_spectrum(torus, "laplacian", k=12)
    mod = mv.compute_spectrum(torus, "modified_dirichlet", k=12)
    area_share = lap.mass[sharp].sum() / lap.mass.sum()  # measured 0.184
    lap_share = _energy_share(lap, sharp, range(1, 11))  # measured 0.17 .. 0.23
    mod_share = _energy_share(mod, sharp, range(10))  # measured 0.036 .. 0.071
    assert np.all(np.abs(lap_share - area_share) < 0.07)  # Laplacian ignores the edges
    assert mod_share.max() < 0.45 * area_share
    assert mod_share.mean() < 0.35 * lap_share.mean()


def _median_strain(mesh, membrane):
    """Median over modes 6-15 of RMS linearised edge strain per unit RMS displacement."""
    spec = mv.compute_spectrum(mesh, "shells", k=16, membrane=membrane)
    e = mesh.edges
    d = mesh.vertices[e[:, 1]] - mesh.vertices[e[:, 0]]
    length2 = np.sum(d * d, axis=1)
    strains = []
    for j in range(6, 16):
        phi = spec.mode(j)
        strain = np.einsum("ij,ij->i", phi[e[:, 1]] - phi[e[:, 0]], d) / length2
        strains.append(np.sqrt(np.mean(strain**2)) / np.sqrt(np.mean(np.sum(phi**2, axis=1))))
    return float(np.median(strains))


def test_fig4_membrane_weight_controls_stretching():
    mesh = mv.load_mesh(ASSETS / "demo_double_torus.obj")
    soft = _median_strain(mesh, 0.01)  # measured 0.394
    stiff = _median_strain(mesh, 100.0)  # measured 0.0877
    assert stiff < 0.3 * soft


def test_fig6_vibration_distance_sees_the_bent_finger():
    mesh = mv.load_mesh(ASSETS / "demo_hand_bent.obj")
    tips = json.loads((ASSETS / "demo_landmarks.json").read_text())["demo_hand_bent"]
    source, bent, straight = tips["finger2"], tips["finger1"], tips["finger0"]
    hks = mv.multiscale_distance(mv.compute_spectrum(mesh, "laplacian", k=100), source)
    vib = mv.multiscale_distance(mv.compute_spectrum(mesh, "shells", k=100), source)
    # measured d(bent tip) / d(straight index tip): heat kernel 0.46, vibration 1.91
    assert hks[bent] / hks[straight] < 0.8  # HKS: the bent tip looks as similar as any
    assert vib[bent] / vib[straight] > 1.4  # vibration: the bent tip stands out


def test_fig8_feature_signature_is_near_zero_on_sharp_features():
    mesh = mv.load_mesh(ASSETS / "demo_machined_part.obj")
    sharp = sharp_vertices(mesh)  # dihedral angle above 30 degrees
    ratios = {}
    for operator in ("modified_dirichlet", "laplacian"):
        _, values = mv.signature(mv.compute_spectrum(mesh, operator, k=100))
        # mean signature on sharp vertices / elsewhere, at two default scales (samples 20, 60)
        ratios[operator] = [values[sharp, i].mean() / values[~sharp, i].mean() for i in (20, 60)]
    # measured: feature signature 0.028 and 0.015; heat kernel signature 1.07 and 1.04
    assert max(ratios["modified_dirichlet"]) < 0.1
    assert min(ratios["laplacian"]) > 0.9


def test_fig9_coarse_vibration_distance_agrees_with_fine():
    import pyvista as pv
    from scipy.spatial import cKDTree

    fine = mv.load_mesh(ASSETS / "demo_hand.obj")
    faces = np.hstack([np.full((fine.n_faces, 1), 3), fine.faces]).ravel()
    decimated = pv.PolyData(np.array(fine.vertices), faces).decimate(0.8)
    coarse = mv.repair_mesh(
        np.asarray(decimated.points), np.asarray(decimated.faces).reshape(-1, 4)[:, 1:]
    )
    assert coarse.n_vertices < 0.22 * fine.n_vertices
    source = json.loads((ASSETS / "demo_landmarks.json").read_text())["demo_hand"]["finger1"]
    tree = cKDTree(coarse.vertices)
    _, source_coarse = tree.query(fine.vertices[source])
    d_fine = mv.multiscale_distance(mv.compute_spectrum(fine, "shells", k=100), source)
    d_coarse = mv.multiscale_distance(
        mv.compute_spectrum(coarse, "shells", k=100), int(source_coarse)
    )
    _, nearest = tree.query(fine.vertices)  # transfer to the fine mesh
    # measured Pearson correlation 0.944 (12895 -> 2580 vertices)
    assert np.corrcoef(d_fine, d_coarse[nearest])[0, 1] > 0.9
