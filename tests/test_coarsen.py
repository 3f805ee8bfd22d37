"""The coarse copy a 3D shells preview starts from (modalviewer.coarsen)."""

import numpy as np
import pytest

from modalviewer.core.primitives import torus


def test_the_first_stage_does_most_collapses_and_leaves_small_meshes_alone():
    pytest.importorskip("fast_simplification")
    from modalviewer.coarsen import FIRST_STAGE_SIZE, _first_stage

    ring = torus(400, 200, minor=0.3)  # 80,000 vertices
    vertices, faces = _first_stage(ring.vertices, ring.faces, 3000)
    assert 0.8 * FIRST_STAGE_SIZE * 3000 <= len(vertices) <= 1.2 * FIRST_STAGE_SIZE * 3000
    small = torus(160, 80, minor=0.3)  # 12,800 vertices: under 8 times the target
    same = _first_stage(small.vertices, small.faces, 3000)
    assert same[0] is small.vertices and same[1] is small.faces


def test_the_two_stage_copy_stays_on_the_surface():
    """The copy of an 80k-vertex torus decimated to about 3000 vertices: every vertex of
    the torus lies within 1 % of the tube's radius of the copy (its located nearest
    point), and the copy has the torus's topology (Euler characteristic 0)."""
    pytest.importorskip("pymeshlab")
    pytest.importorskip("fast_simplification")
    from modalviewer.coarsen import decimate_and_locate

    ring = torus(400, 200, minor=0.3)
    coarse, triangles, barycentric = decimate_and_locate(ring.vertices, ring.faces, 3000)
    assert 2800 <= coarse.n_vertices <= 3300
    assert coarse.n_vertices - len(coarse.edges) + coarse.n_faces == 0
    nearest = np.einsum("nk,nkd->nd", barycentric, coarse.vertices[coarse.faces[triangles]])
    assert np.linalg.norm(nearest - ring.vertices, axis=1).max() < 0.01 * 0.3


def test_the_reason_a_preview_does_not_start_from_a_coarse_copy(monkeypatch):
    """preview_copy_refusal gives the status line's words: none for the 3D shells of a
    mesh big enough for a copy (with pymeshlab), else why not (the operator, the mesh's
    size, the exact factor's memory, the optional library)."""
    import importlib.util

    from modalviewer import coarsen
    from modalviewer.core.operators import OperatorInfo

    refusal = coarsen.preview_copy_refusal
    assert refusal(200_000, "laplacian", 100) == "no coarse copy for this operator"
    # 100 modes want a copy of 3000 vertices: more than a quarter of 10k
    assert refusal(10_000, "shells", 100) == "the mesh is too small for a coarse copy to save work"
    big = refusal(200_000, "shells", 100)
    if importlib.util.find_spec("pymeshlab") is None:
        assert big == "no coarse copy without the optional pymeshlab"
    else:
        assert big is None
    monkeypatch.setattr(OperatorInfo, "factor_out_of_core", lambda self, n, k: True)
    assert refusal(200_000, "shells", 100) == "the exact solve's factor would not fit in memory"
