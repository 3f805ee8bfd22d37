"""Meshes in from other libraries (:func:`as_mesh`), an operator's matrices
(:func:`operator_matrices`) and point data (:func:`to_pyvista`) out.  trimesh, pyvista
and meshio objects are recognised by their type's module, without importing them."""

from __future__ import annotations

import os

import numpy as np
import scipy.sparse as sp

from .core.assembly import operator_matrices as _operator_matrices
from .core.mesh import Mesh
from .core.spectrum import Spectrum
from .extras import extra_needed
from .io import load_mesh, mesh_from_arrays, meshio_arrays, pyvista_arrays


def as_mesh(obj, repair: bool = True, name: str = "") -> Mesh:
    """A :class:`Mesh` from arrays or another library's mesh object.

    ``obj``: a :class:`Mesh` (returned as it is), a file (read by
    :func:`~modalviewer.io.load_mesh`), ``(vertices (n, 3), faces (m, 3))``, a
    ``trimesh.Trimesh``, a ``pyvista.PolyData`` (other data sets: their outer surface;
    polygons triangulated, as ``mesh.report`` says) or a ``meshio.Mesh`` (its triangles;
    quads and polygons triangulated, volume cells skipped).  ``repair`` as in
    :func:`~modalviewer.io.load_mesh`; ``name`` names the mesh in the report (default: the
    object's type).  Vertex i of the object is vertex i of the mesh (:mod:`.core.mesh`).
    MeshError for an object that holds no triangle surface, TypeError for another kind.
    """
    if isinstance(obj, Mesh):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        return load_mesh(obj, repair=repair)
    module = type(obj).__module__.split(".")[0]  # recognised without importing the library
    notes = []
    if module == "trimesh":
        vertices, faces = np.asarray(obj.vertices, np.float64), np.asarray(obj.faces, np.int64)
    elif module in ("pyvista", "vtkmodules"):
        with extra_needed("as_mesh of a VTK object"):
            import pyvista as pv

            vertices, faces, notes = pyvista_arrays(pv.wrap(obj))
    elif module == "meshio":
        vertices, faces, notes = meshio_arrays(obj)
    elif isinstance(obj, (tuple, list)) and len(obj) == 2:
        vertices, faces = np.asarray(obj[0]), np.asarray(obj[1])
    else:
        raise TypeError(
            "as_mesh takes a Mesh, a file, a (vertices, faces) pair of arrays, a "
            f"trimesh.Trimesh, a pyvista.PolyData or a meshio.Mesh, not {type(obj).__name__}"
        )
    source = name or ("arrays" if isinstance(obj, (tuple, list)) else type(obj).__name__)
    return mesh_from_arrays(vertices, faces, source, repair=repair, notes=notes)


def operator_matrices(mesh, operator: str, bending: float = 1.0, membrane: float = 1.0):
    """``(K, M)``: the sparse matrices of ``operator``'s eigenproblem ``K x = lambda M x``.

    K is CSR, symmetric positive semi-definite (its null space is the one
    ``spec.null_space_dimension`` counts); M the lumped mass, a DIA matrix of the vertex
    areas repeated for each unknown: ``(n,)`` unknowns, or ``(3 n,)`` ordered x, y, z per
    vertex for vector modes, as ``spec.modes`` reshaped.  ``eigsh(K, k, M, sigma=-s)``
    for a small ``s > 0`` gives :func:`~modalviewer.compute_spectrum`'s spectrum (up to
    signs and bases of eigenspaces).  ``bending``, ``membrane``: the shells weights.
    Vertices no face uses and merged duplicates have empty rows in K and zero mass.
    """
    mesh = as_mesh(mesh)
    solver = mesh.solver_mesh
    K, mass = _operator_matrices(solver, operator, bending, membrane)
    K, mass = sp.csr_matrix(K), np.asarray(mass, dtype=np.float64)
    if solver is not mesh:  # the input's numbering: empty rows and zero mass where unused
        per = K.shape[0] // solver.n_vertices
        rows = (per * np.asarray(solver.file_vertices)[:, None] + np.arange(per)).ravel()
        n = per * mesh.n_vertices
        P = sp.csr_matrix((np.ones(len(rows)), (rows, np.arange(len(rows)))), shape=(n, len(rows)))
        K = sp.csr_matrix(P @ K @ P.T)
        mass = P @ mass
    return K, sp.diags(mass, format="dia")


@extra_needed("mv.to_pyvista")
def to_pyvista(mesh, spectrum: Spectrum | None = None, fields: dict | None = None):
    """A ``pyvista.PolyData`` of ``mesh``, one point per input vertex in the input's order
    (NaN values at ``mesh.unused``), with ``spectrum``'s modes as ``"mode_<j>"`` ((n,) or
    (n, 3)), its masses as ``"mass"`` and eigenvalues as ``field_data["eigenvalues"]``,
    and ``fields`` (name -> (n,) or (n, c) array) as point arrays."""
    import pyvista as pv

    mesh = as_mesh(mesh)
    n = mesh.n_vertices
    poly = pv.PolyData.from_regular_faces(np.array(mesh.vertices), mesh.faces)
    if spectrum is not None:
        if spectrum.n_vertices != n:
            raise ValueError(
                f"the spectrum has {spectrum.n_vertices} vertices, the mesh {n}: it belongs "
                "to another mesh"
            )
        for j in range(spectrum.k):
            poly.point_data[f"mode_{j}"] = np.ascontiguousarray(spectrum.mode(j))
        poly.point_data["mass"] = np.asarray(spectrum.mass)
        poly.field_data["eigenvalues"] = np.asarray(spectrum.eigenvalues)
    for name, values in (fields or {}).items():
        values = np.asarray(values)
        if len(values) != n:
            raise ValueError(f"field {name!r} has {len(values)} values, the mesh {n} vertices")
        poly.point_data[str(name)] = values
    return poly
