"""The viewer suggests the robust Laplacian where the cotan weights go negative, and
computes it like any operator."""

import numpy as np
import pytest

import modalviewer as mv
from benchmarks.slivers import add_slivers
from modalviewer.core.primitives import icosphere
from modalviewer.viewer import Viewer, wording


def test_the_note_counts_negative_cotan_weights_and_the_robust_spectrum_computes():
    pytest.importorskip("robust_laplacian")
    v, f = add_slivers(icosphere(3), needles=20, caps=20, eps=1e-8, seed=2)
    viewer = Viewer()
    try:
        viewer.set_mesh(icosphere(3))
        assert wording.negative_weights_note(viewer.state) == ""
        viewer.set_mesh(mv.Mesh(v, f))
        assert wording.negative_weights_note(viewer.state) == (
            "This mesh has 46 negative cotan weights: try the Laplacian (robust, intrinsic "
            "Delaunay), whose weights are never negative."
        )
        spec = viewer.compute("laplacian_robust", k=12)
        expected = mv.compute_spectrum(viewer.state.mesh, "laplacian_robust", k=12)
        np.testing.assert_allclose(spec.eigenvalues, expected.eigenvalues, rtol=1e-9, atol=1e-12)
        viewer.show_mode(3, "laplacian_robust")
        assert "Laplacian (robust, intrinsic Delaunay), mode 3" in wording.legend(viewer.state)
    finally:
        viewer.close()
