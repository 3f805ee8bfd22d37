"""The scalar colouring a 3D vibration mode (modalviewer.viewer.mode_scalar)."""

import numpy as np
import pytest
import trimesh

from modalviewer.core.laplacian import lumped_masses, stiffness_matrix, vertex_normals
from modalviewer.core.mesh import Mesh
from modalviewer.core.primitives import icosphere
from modalviewer.viewer.mode_scalar import (
    smoothed_normals,
    vector_mode_scalar,
)


def _box(size=(2.0, 1.0, 1.5), edge=0.06) -> Mesh:
    """A closed box with sharp edges, about ``edge`` long triangles."""
    box = trimesh.creation.box(extents=size)
    v, f = trimesh.remesh.subdivide_to_size(box.vertices, box.faces, max_edge=edge)
    merged = trimesh.Trimesh(v, f, process=True)
    return Mesh(np.asarray(merged.vertices), np.asarray(merged.faces))


def _roughness(mesh, f):
    """Rayleigh quotient f^T S f / f^T M f: large for a field that changes quickly."""
    s, m = stiffness_matrix(mesh), lumped_masses(mesh)
    return float(f @ (s @ f)) / float(f @ (m * f))


def test_smoothed_normals_on_a_sphere_are_the_normals():
    mesh = icosphere(3)
    n = smoothed_normals(mesh)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0)
    # a sphere's normals are an eigenfunction of the diffusion: only their length changes
    assert np.min(np.einsum("ij,ij->i", n, vertex_normals(mesh))) > 0.9999


def test_normal_component_against_smoothed_normals_is_smoother_at_sharp_edges():
    mesh = _box()
    # a smooth displacement: a rotation about the z axis plus a bend
    v = mesh.vertices
    phi = np.column_stack([-v[:, 1], v[:, 0], 0.3 * v[:, 0] ** 2])
    plain = vector_mode_scalar(phi, vertex_normals(mesh))
    smooth = vector_mode_scalar(phi, smoothed_normals(mesh))
    # roughness 144 -> 38: the plain normals jump at the edges, the smoothed ones turn
    assert _roughness(mesh, smooth) < 0.5 * _roughness(mesh, plain)
    # in the middle of the faces, five edge lengths from the edges, both agree to 1 %
    half = 0.5 * np.array([2.0, 1.0, 1.5])
    on_face = np.abs(np.abs(v) - half) < 1e-9
    far = np.sum(np.abs(np.abs(v) - half) > 0.3, axis=1) == 2
    middle = on_face.any(axis=1) & far
    assert middle.sum() > 50
    assert np.max(np.abs(smooth[middle] - plain[middle])) < 1e-2 * np.max(np.abs(plain))
    magnitude = vector_mode_scalar(phi, None, "magnitude")
    assert np.allclose(magnitude, np.linalg.norm(phi, axis=1))
    with pytest.raises(ValueError, match="unknown colouring"):
        vector_mode_scalar(phi, None, "curl")
