"""Exactly known null spaces: built per component, deflated in the eigensolver, returned as
exact zero modes counted in k, and flagged by one zero-mode rule whatever k is."""

import warnings

import numpy as np
import pytest
import scipy.linalg as la

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.eigen import (
    EigenError,
    relative_residuals,
    rounding_floors,
    solve_lowest,
    zero_modes,
)
from modalviewer.core.krylov import block_krylov_schur
from modalviewer.core.nullspace import null_space
from modalviewer.core.pipeline import ZeroModesWarning
from modalviewer.core.primitives import grid_plate, icosphere, torus


def combine(*meshes):
    v, f, offset = [], [], 0
    for m in meshes:
        v.append(m.vertices)
        f.append(m.faces + offset)
        offset += m.n_vertices
    return mv.Mesh(np.vstack(v), np.vstack(f))


def moved(mesh, scale=1.0, shift=(0.0, 0.0, 0.0), rotation=None):
    v = mesh.vertices * scale
    if rotation is not None:
        v = v @ rotation.T
    return mv.Mesh(v + np.asarray(shift), mesh.faces)


TILT = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, -0.8], [0.0, 0.8, 0.6]])


@pytest.fixture(scope="module")
def four_parts():
    """Two spheres, a torus and a tilted flat plate: 4 components, 1 of them flat."""
    s = icosphere(2)  # 162 vertices
    return combine(
        s,
        moved(s, 0.6, (3.0, 0.0, 0.0)),
        moved(torus(24, 12, 1.0, 0.35), 1.0, (0.0, 4.0, 0.0)),
        moved(grid_plate(8, 8), 2.0, (0.0, 0.0, 5.0), TILT),
    )


@pytest.fixture(scope="module")
def three_spheres():
    """Three ellipsoids with three different axes each (no multiple eigenvalues: a block
    Krylov method with blocks of b vectors finds at most b copies of one eigenvalue
    before rounding brings in more, so exact copies are kept out of this test)."""
    s = icosphere(2)
    return combine(
        moved(s, np.array([1.0, 0.8, 1.3])),
        moved(s, np.array([0.7, 0.9, 0.6]), (3.0, 0, 0)),
        moved(s, np.array([1.2, 1.0, 0.9]), (0, 4.0, 0)),
    )


def dense_lowest(K, mass, count):
    return la.eigh(K.toarray(), np.diag(mass), eigvals_only=True, subset_by_index=[0, count - 1])


@pytest.mark.parametrize(
    "operator, per_component",
    [
        ("laplacian", [1, 1, 1, 1]),
        ("shells", [6, 6, 6, 6]),
        ("modified_dirichlet", [0, 0, 0, 1]),  # f N constant: only on the flat plate
        ("shells_normal", [0, 0, 0, 3]),  # f N rigid: 1, x, y on the flat plate
    ],
)
def test_null_space_per_component_matches_the_dense_spectrum(four_parts, operator, per_component):
    K, mass = operator_matrices(four_parts, operator)
    ns = null_space(four_parts, operator, K, mass)
    assert ns.n_components == 4
    assert ns.per_component.tolist() == per_component
    d = ns.dimension
    Z = ns.vectors.toarray()
    np.testing.assert_allclose(Z.T @ (mass[:, None] * Z), np.eye(d), atol=1e-12)
    assert np.abs(K @ Z).max(initial=0.0) <= 1e-13 * abs(K).max()
    # the dense spectrum has exactly d zero eigenvalues: nothing is missed or invented
    lam = dense_lowest(K, mass, d + 1)
    scale = np.median(K.diagonal() / mass)
    assert np.all(np.abs(lam[:d]) < 1e-9 * scale)
    assert lam[d] > 1e-6 * scale  # the zeros are below 1e-9 * scale


def test_rigid_motions_span_translations_and_rotations(three_spheres):
    K, mass = operator_matrices(three_spheres, "shells")
    Z = null_space(three_spheres, "shells", K, mass).vectors.toarray()
    x = three_spheres.vertices
    first = np.flatnonzero(three_spheres.component_labels == 0)
    rows = (3 * first[:, None] + np.arange(3)).ravel()
    fields = [np.tile(e, len(first)) for e in np.eye(3)]
    fields += [np.cross(axis, x[first] - [0.2, 0.1, 0.0]).ravel() for axis in np.eye(3)]
    for field in fields:  # each rigid motion of component 0 lies in the span
        coef, *_ = np.linalg.lstsq(Z[rows], field, rcond=None)
        assert np.linalg.norm(Z[rows] @ coef - field) < 1e-12 * np.linalg.norm(field)


def test_null_space_larger_than_k_is_answered_without_iteration(three_spheres):
    # 18 rigid motions, 10 modes asked: exact zeros, no factorisation, flagged as zero modes
    with pytest.warns(ZeroModesWarning, match="all 10 modes are exact zero modes.*18 modes"):
        spec = mv.compute_spectrum(three_spheres, "shells", k=10)
    assert spec.eigenvalues.tolist() == [0.0] * 10
    assert spec.parameters["method"] == "null space (no iteration)"
    assert spec.parameters["seconds_by_stage"].get("factorisation", 0.0) == 0.0
    assert spec.zero_mode_mask().all()
    assert spec.null_space_dimension == 10
    X = spec.modes.reshape(-1, 10)
    mass = np.repeat(spec.mass, 3)
    np.testing.assert_allclose(X.T @ (mass[:, None] * X), np.eye(10), atol=1e-12)
    assert spec.residuals.max() < 1e-12
    assert "3 connected components" in spec.parameters["null_space"]
    assert "18 modes" in spec.parameters["null_space"]


@pytest.mark.filterwarnings("ignore::modalviewer.core.pipeline.ZeroModesWarning")
@pytest.mark.parametrize("k", [17, 18, 19, 30])
def test_null_space_around_k_is_never_half_found(three_spheres, k):
    # 3 spheres: 18 rigid motions (5844 unknowns, the sparse solver) for k below,
    # at and above the null-space dimension
    K, mass = operator_matrices(three_spheres, "shells")
    spec = mv.compute_spectrum(three_spheres, "shells", k=k)
    lam = spec.eigenvalues
    d = min(k, 18)
    assert np.all(lam[:d] == 0.0)
    assert spec.zero_mode_mask().sum() == d
    assert np.all(lam[d:] > 1e-3 * lam.max(initial=1.0))
    X = spec.modes.reshape(-1, k)
    # the whole returned set is Mass-orthonormal (null vectors against the others too)
    np.testing.assert_allclose(X.T @ (mass[:, None] * X), np.eye(k), atol=1e-10)
    R = K @ X - mass[:, None] * X * lam
    scale = np.where(lam > 0, lam, np.median(K.diagonal() / mass))
    rel = np.linalg.norm(R, axis=0) / (scale * np.linalg.norm(mass[:, None] * X, axis=0))
    assert rel.max() < 1e-8
    if k > 18:  # the non-zero ones agree with a dense solve
        reference = dense_lowest(K, mass, k)
        np.testing.assert_allclose(lam[18:], reference[18:], rtol=1e-9)


def test_laplacian_one_constant_per_component_sparse_and_dense(four_parts):
    K, mass = operator_matrices(four_parts, "laplacian")
    ns = null_space(four_parts, "laplacian", K, mass)
    reference = dense_lowest(K, mass, 12)
    for limit in (0, 10**6):  # Krylov in the complement, dense in the complement
        res = solve_lowest(K, mass, 12, null_space=ns.vectors, dense_limit=limit)
        assert res.null_dim == 4 and np.all(res.eigenvalues[:4] == 0.0)
        np.testing.assert_allclose(res.eigenvalues[4:], reference[4:], rtol=1e-9)
        X = res.vectors
        np.testing.assert_allclose(X.T @ (mass[:, None] * X), np.eye(12), atol=1e-10)
        for c in range(4):  # the null vectors are the components' constants
            on = four_parts.component_labels == c
            col = X[:, c]
            assert np.ptp(col[on]) < 1e-12 and np.all(col[~on] == 0.0)


def test_zero_mode_mask_does_not_depend_on_k():
    # one sphere, shells: the six rigid motions are zero modes for k = 6 as for k = 20
    # (without deflation they came out at about 1e-12 and k = 6 flagged none of them)
    mesh = icosphere(3)
    for k in (6, 7, 20):
        spec = mv.compute_spectrum(mesh, "shells", k=k)
        mask = spec.zero_mode_mask()
        assert mask[:6].all() and not mask[6:].any(), k
        assert spec.null_space_dimension == 6


def test_low_vibrations_of_fine_meshes_are_not_zero_modes():
    # numbers of the shells on cheburashka subdivided twice (107k vertices): the typical
    # eigenvalue size is 1.58e11, the first vibrations 631 to 1566; 1e-8 of the typical
    # size (the rule before) called them zero modes and exempted them from the check
    lam = np.array([0.0] * 6 + [631.02, 1177.83, 1409.83, 1566.29, 2549.8, 3402.11])
    mask = zero_modes(lam, lam_scale=1.58e11, null_dim=6)
    assert mask.tolist() == [True] * 6 + [False] * 6
    # undeflated rounding noise is still a zero mode
    assert zero_modes(np.array([3e-2, 631.0]), lam_scale=1.58e11).tolist() == [True, False]


def test_saved_spectrum_keeps_the_zero_modes(three_spheres, tmp_path):
    with pytest.warns(ZeroModesWarning):
        spec = mv.compute_spectrum(three_spheres, "shells", k=12)
    mv.save_spectrum(spec, tmp_path / "s.npz")
    back = mv.load_spectrum(tmp_path / "s.npz")
    assert back.null_space_dimension == 12
    assert back.zero_mode_mask().all()
    assert back.parameters["null_space"] == spec.parameters["null_space"]


def test_signature_leaves_out_every_deflated_mode(three_spheres):
    spec = mv.compute_spectrum(three_spheres, "laplacian", k=8)
    times, values = mv.signature(spec)
    used = spec.modes[:, 3:] ** 2
    lam = spec.eigenvalues[3:]
    expected = used @ np.exp(-np.outer(lam, times))
    np.testing.assert_allclose(values, expected, rtol=1e-12)


def test_no_convergence_gives_no_wrong_advice():
    rng = np.random.default_rng(1)
    theta = np.linspace(1.0, 0.99, 400)  # no gap: cannot converge in two restarts
    Q = np.linalg.qr(rng.standard_normal((400, 400)))[0]
    A = (Q * theta) @ Q.T
    with pytest.raises(EigenError, match="did not converge") as info:
        block_krylov_schur(
            lambda V: A @ V, 400, 6, keep=8, block=4, max_basis=16, tol=1e-12,
            report=lambda s, f: None, max_restarts=2,
        )  # fmt: skip
    assert "fewer modes" not in str(info.value)


def test_bad_null_space_is_refused(three_spheres):
    K, mass = operator_matrices(three_spheres, "laplacian")
    with pytest.raises(ValueError, match="Mass-orthonormal"):
        solve_lowest(K, mass, 5, null_space=np.ones((K.shape[0], 1)))
    with pytest.raises(ValueError, match="rows"):
        solve_lowest(K, mass, 5, null_space=np.ones((3, 1)))


def test_rounding_floor_bounds_what_rounding_does(three_spheres):
    K, mass = operator_matrices(three_spheres, "shells")
    lam, X = la.eigh(K.toarray(), np.diag(mass), subset_by_index=[18, 23])
    rng = np.random.default_rng(0)
    rounded = X * (1.0 + np.finfo(float).eps * rng.uniform(-1, 1, X.shape))
    floors = rounding_floors(K, mass, lam, rounded)
    res = relative_residuals(K, mass, lam, rounded)
    # LAPACK's vectors and their rounding land at 1 to 3 times the floor (measured 1.4-2.7)
    assert np.all(res <= 4.0 * floors) and np.all(floors < 1e-10)
    noisy = X + 1e-6 * rng.standard_normal(X.shape) * np.abs(X).max()
    assert np.all(relative_residuals(K, mass, lam, noisy) > 1e3 * floors)


def test_residual_check_accepts_the_rounding_floor_and_rejects_garbage(monkeypatch):
    import modalviewer.core.pipeline as pipeline

    s = icosphere(2)  # 486 unknowns: the dense solver, residuals at the rounding floor
    ellipsoid = mv.Mesh(s.vertices * [1.0, 0.8, 1.3], s.faces)
    monkeypatch.setattr(pipeline, "RESIDUAL_LIMIT", 1e-300)  # every mode is "above" it
    spec = mv.compute_spectrum(ellipsoid, "shells", k=30)
    assert spec.parameters["modes_at_rounding_floor"] == 24
    real = pipeline.solve_lowest

    def spoiled(*args, **kwargs):
        result = real(*args, **kwargs)
        result.vectors[:, -1] += 1e-6 * result.vectors[:, -2]
        result.residuals[-1] = 1e-3
        return result

    monkeypatch.setattr(pipeline, "solve_lowest", spoiled)
    with pytest.raises(EigenError, match="above the rounding floor"):
        mv.compute_spectrum(ellipsoid, "shells", k=30)


def _spheres_sharing_a_vertex() -> mv.Mesh:
    """Two icospheres touching at one vertex, which they share: one connected component
    through edges, two parts through faces."""
    a = icosphere(1)
    p = a.vertices[0]
    b = -a.vertices + 2.0 * p  # a point reflection through p: b's vertex 0 lands on p
    keep = np.arange(1, len(b))
    index = np.empty(len(b), dtype=np.int64)
    index[0] = 0
    index[keep] = len(a.vertices) + np.arange(len(keep))
    vertices = np.vstack([a.vertices, b[keep]])
    faces = np.vstack([a.faces, index[a.faces[:, ::-1]]])  # the reflection turns b inside out
    return mv.Mesh(vertices, faces)


def test_a_part_held_at_a_single_vertex_adds_three_zero_modes_to_the_shells():
    """The panel counted only rigid motions per component (18 for a teapot whose
    spectrum had 21 zero modes): a part meeting the rest at one vertex can rotate
    about it."""
    mesh = _spheres_sharing_a_vertex()
    assert mesh.n_components == 1 and mesh.n_face_components == 2
    assert icosphere(1).n_face_components == 1
    K, mass = operator_matrices(mesh, "shells")
    lam = la.eigh(K.toarray(), np.diag(mass), eigvals_only=True)
    assert int(np.sum(lam < 1e-8 * lam.max())) == 6 + 3


def spheres_touching_at_a_vertex():
    """Two icospheres sharing one vertex: one component whose halves rotate freely about
    it, so 3 zero modes beyond the 6 rigid motions (not known in advance, not deflated)."""
    s = icosphere(2)
    v, n = s.vertices, s.n_vertices
    top, bottom = int(np.argmax(v[:, 2])), int(np.argmin(v[:, 2]))
    keep = np.delete(np.arange(n), bottom)
    remap = np.full(n, -1)
    remap[keep] = n + np.arange(n - 1)
    remap[bottom] = top
    return mv.Mesh(
        np.vstack([v, (v - v[bottom] + v[top])[keep]]), np.vstack([s.faces, remap[s.faces]])
    )


def test_a_spectrum_of_rounding_level_eigenvalues_is_flagged():
    mesh = spheres_touching_at_a_vertex()
    assert mesh.n_components == 1
    with pytest.warns(ZeroModesWarning, match="all 8 eigenvalues are null-space values: 6 exact"):
        spec = mv.compute_spectrum(mesh, "shells", k=8)
    assert spec.null_space_dimension == 6
    assert np.abs(spec.eigenvalues).max() < 1e-9  # 2.3e-13 measured; typical size 2.1e3
    assert spec.zero_mode_mask().all()
    with warnings.catch_warnings():
        warnings.simplefilter("error", ZeroModesWarning)
        spec = mv.compute_spectrum(mesh, "shells", k=10)  # the first vibration, 1.98
    assert spec.eigenvalues[-1] > 1.0 and spec.zero_mode_mask().sum() == 9


def test_k_not_above_the_null_space_of_one_component_is_flagged():
    with pytest.warns(ZeroModesWarning, match="all 6 modes are exact zero modes.*k is not larger"):
        spec = mv.compute_spectrum(icosphere(2), "shells", k=6)
    assert spec.eigenvalues.tolist() == [0.0] * 6
    with pytest.warns(ZeroModesWarning, match="the only mode is an exact zero mode"):
        mv.compute_spectrum(icosphere(2), "laplacian", k=1)


def test_too_few_modes_for_the_null_space_advise_enough_to_pass_it():
    """Four 3D shells modes of one closed piece are four of its six rigid motions: the
    advice must ask for seven, not five."""
    import warnings

    import modalviewer as mv
    from modalviewer.core.pipeline import ZeroModesWarning
    from modalviewer.core.primitives import icosphere

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mv.compute_spectrum(icosphere(2), "shells", 4)
    messages = [str(w.message) for w in caught if issubclass(w.category, ZeroModesWarning)]
    assert len(messages) == 1
    assert "Ask for at least 7 modes" in messages[0], messages[0]
