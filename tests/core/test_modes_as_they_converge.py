"""``compute_spectrum(..., on_modes=...)``: the eigensolver's pairs handed over as they
converge, lowest first, equal to the finished spectrum's (values, modes, clusters of equal
eigenvalues as subspaces, the exact null vectors first); and meshes of many parts, where
k is just above the null space."""

import numpy as np
import pytest
import scipy.linalg as la

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.primitives import icosphere


def handed_over(mesh, operator, k):
    calls = []
    final = mv.compute_spectrum(mesh, operator, k, on_modes=calls.append)
    return calls, final


def flat(spec):
    return spec.modes.reshape(-1, spec.k)


def mass_of(spec):
    rows = flat(spec).shape[0]
    return np.repeat(spec.mass, rows // spec.mass.size)


def check_equal_to_final(calls, final, value_rtol=1e-8, mode_tol=1e-6):
    """Every call's modes are the final ones: values, Mass-orthonormality, and each
    mode inside the span of the final modes of its eigenvalue (a cluster as a subspace);
    no call splits a cluster of equal final eigenvalues."""
    m = mass_of(final)
    F = flat(final)
    lam_f = final.eigenvalues
    scale = np.abs(lam_f).max()
    zero_f = final.zero_mode_mask()
    for spec in calls[:-1]:
        j = spec.k
        assert not spec.is_complete and spec.modes_requested == final.k
        nonzero = ~zero_f[:j]
        rel = np.abs(spec.eigenvalues - lam_f[:j]) / np.abs(lam_f[:j]).clip(1e-300)
        assert rel[nonzero].max(initial=0.0) <= value_rtol
        assert np.abs(spec.eigenvalues[~nonzero]).max(initial=0.0) <= 1e-8 * scale
        P = flat(spec)
        assert np.abs(P.T @ (m[:, None] * P) - np.eye(j)).max() <= 1e-8
        for i in range(j):
            if zero_f[i]:
                same = np.flatnonzero(zero_f)
            else:
                same = np.flatnonzero(np.abs(lam_f - lam_f[i]) <= 1e-6 * abs(lam_f[i]))
            # Mass-norm distance of mode i to the span of the final modes of its value
            coeffs = F[:, same].T @ (m * P[:, i])
            rest = P[:, i] - F[:, same] @ coeffs
            assert np.sqrt(rest @ (m * rest)) <= mode_tol
        if j < final.k and not zero_f[j - 1]:
            # the first mode not handed over is not equal to the last one handed over
            assert abs(lam_f[j] - lam_f[j - 1]) > 1e-6 * abs(lam_f[j - 1])


@pytest.mark.parametrize("operator", ["laplacian", "modified_dirichlet", "shells"])
def test_modes_handed_over_equal_the_final_ones(spot, operator):
    calls, final = handed_over(spot, operator, 40)
    counts = [c.k for c in calls]
    assert len(calls) >= 3, counts  # modes arrive in several steps before the end
    assert counts == sorted(set(counts)) and counts[-1] == 40
    # each hand-over reads the whole Krylov basis: after the first, each brings at least
    # half as many pairs of the iteration as came before (krylov.HANDOVER_GROWTH)
    nulls = final.null_space_dimension
    for before, after in zip(counts[:-2], counts[1:-1], strict=True):
        assert after - before >= 0.5 * (before - nulls), counts
    assert calls[-1] is final and final.is_complete
    nulls = final.null_space_dimension
    assert nulls == {"laplacian": 1, "modified_dirichlet": 0, "shells": 6}[operator]
    assert counts[0] > nulls  # the null vectors come first, with the first modes
    assert np.all(calls[0].eigenvalues[:nulls] == 0.0)
    assert calls[0].null_space_dimension == nulls
    # residuals are computed once, for the finished spectrum
    assert all(np.isnan(c.residuals).all() for c in calls[:-1])
    assert np.isfinite(final.residuals).all() and final.residuals[nulls:].max() <= 1e-8
    check_equal_to_final(calls, final)


def test_equal_eigenvalues_are_handed_over_as_whole_clusters():
    """A sphere's Laplacian keeps the icosahedron's symmetry: clusters of 3, 4 and 5
    equal eigenvalues."""
    sphere = icosphere(4)  # 2562 vertices: solved by the Krylov iteration
    calls, final = handed_over(sphere, "laplacian", 30)
    lam = final.eigenvalues[1:]
    sizes = np.diff(np.flatnonzero(np.r_[True, np.diff(lam) > 1e-6 * lam[1:], True]))
    assert {3, 4, 5} <= set(sizes.tolist())  # the test has clusters to split
    assert len(calls) >= 2
    check_equal_to_final(calls, final)


def many_parts(count: int) -> mv.Mesh:
    """``count`` ellipsoids of different axes (no eigenvalue repeats between parts)."""
    s = icosphere(1)  # 42 vertices
    vertices = [
        s.vertices * [1 + 0.03 * i, 0.8 + 0.011 * i, 1.3 - 0.013 * i] + [3.0 * i, 0, 0]
        for i in range(count)
    ]
    faces = [s.faces + s.n_vertices * i for i in range(count)]
    return mv.Mesh(np.vstack(vertices), np.vstack(faces))


@pytest.mark.filterwarnings("ignore::modalviewer.core.pipeline.ZeroModesWarning")
def test_k_just_above_a_large_null_space_is_solved():
    """44 parts: 264 rigid motions; 284 modes leave 20 for the iteration, whose basis
    has fewer columns than the null vectors."""
    mesh = many_parts(44)
    spec = mv.compute_spectrum(mesh, "shells", 284)
    assert spec.null_space_dimension == 264
    assert np.count_nonzero(spec.zero_mode_mask()) == 264
    assert np.all(spec.eigenvalues[264:] > 0)
    assert spec.residuals[264:].max() <= 1e-8


@pytest.fixture(scope="module")
def twelve_parts():
    mesh = many_parts(12)  # 504 vertices, 1512 unknowns: above the dense solver's limit
    K, mass = operator_matrices(mesh, "shells")
    exact = la.eigh(K.toarray(), np.diag(np.asarray(mass)), eigvals_only=True)
    return mesh, exact


@pytest.mark.filterwarnings("ignore::modalviewer.core.pipeline.ZeroModesWarning")
@pytest.mark.parametrize("extra", [0, 1, 2, 5, 11, 30, 72])
def test_any_k_from_the_null_space_to_twice_it(twelve_parts, extra):
    mesh, exact = twelve_parts
    d = 72
    calls, spec = handed_over(mesh, "shells", d + extra)
    assert spec.k == d + extra and spec.null_space_dimension == d
    assert np.count_nonzero(spec.zero_mode_mask()) == d
    rest = spec.eigenvalues[d:]
    assert np.allclose(rest, exact[d : d + extra], rtol=1e-8, atol=0)
    assert calls[-1] is spec
    check_equal_to_final(calls, spec)
