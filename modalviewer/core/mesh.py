"""The immutable triangle :class:`Mesh`: validation (never repair: that is
:func:`.cleaning.repair_mesh`) and topology queries.

One vertex numbering, the user's own (row i of the arrays, the i-th vertex of the file).
A vertex no face uses (:attr:`Mesh.unused`) has no value: NaN in every per-vertex result,
an empty stiffness row and a zero mass, as in libigl; a merged duplicate
(:attr:`Mesh.merged_into`) takes the values of its vertex.  The solvers work on
:attr:`Mesh.solver_mesh`, the used vertices only, which maps results back.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components


class MeshError(ValueError):
    """Raised for input that cannot be a triangle surface, with a message for a user."""


@dataclass
class MeshReport:
    """What loading found and repaired, as sentences a user understands."""

    source: str = ""
    messages: list[str] = field(default_factory=list)

    def add(self, message: str) -> None:
        self.messages.append(message)

    def __str__(self) -> str:
        head = f"{self.source}: " if self.source else ""
        return head + (" ".join(self.messages) or "no problems found.")

    def __bool__(self) -> bool:  # a report is always worth showing
        return True


def _plural(count: int, word: str) -> str:
    if count == 1:
        return f"{count} {word}"
    if word.endswith("vertex"):
        return f"{count} {word[:-6]}vertices"
    return f"{count} {word}s"


def _unused_words(index: int) -> str:
    return (
        f"vertex {index} (counting from 0) is used by no face: it has no value, so no "
        "distances, signatures or modes there (mesh.unused lists such vertices)"
    )


def triangle_areas(x: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m,) triangle areas."""
    n = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
    return 0.5 * np.linalg.norm(n, axis=1)


def triangle_quality(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m,) quality ``4 sqrt(3) area / (l0^2 + l1^2 + l2^2)`` of each triangle: 1
    equilateral, about 2 h / L for a needle or cap of longest edge L and height h."""
    v, f = np.asarray(vertices, dtype=np.float64), np.asarray(faces)
    sq = sum(((v[f[:, (c + 1) % 3]] - v[f[:, c]]) ** 2).sum(axis=1) for c in range(3))
    return 4.0 * np.sqrt(3.0) * triangle_areas(v, f) / np.maximum(sq, np.finfo(float).tiny)


def checked_arrays(vertices, faces, polygons: bool = False):
    """``(vertices (n, 3) float64, faces (m, 3) int64, note)`` of raw arrays, checked and
    never reshaped (a (3, m) array is refused: ``faces.T`` is meant); with ``polygons``
    (m, p > 3) faces are fanned into triangles and ``note`` says so.  A :class:`MeshError`
    naming what is wrong and how to fix it otherwise."""
    try:
        v = np.array(vertices, dtype=np.float64)
        f = np.asarray(faces)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"vertices and faces must be numeric arrays ({exc})") from None
    if v.size == 0:
        raise MeshError("the mesh has no vertices")
    if v.ndim != 2 or v.shape[1] != 3:
        hint = "; pass vertices.T" if v.ndim == 2 and v.shape[0] == 3 else ""
        raise MeshError(
            f"vertices must be an (n, 3) array of x, y, z coordinates; got shape {v.shape}{hint}"
        )
    if f.size == 0:
        raise MeshError(
            f"the mesh has {_plural(len(v), 'vertex')} but no faces: a point cloud is not "
            "a surface (reconstruct a surface from it first)"
        )
    if f.ndim != 2 or f.shape[1] < 3:
        raise MeshError(f"faces must be an (m, 3) array of vertex indices; got shape {f.shape}")
    if f.dtype.kind not in "iuf":  # not bool, complex or object
        raise MeshError(f"face indices must be integers; got an array of {f.dtype}")
    if f.dtype.kind == "f":
        whole = np.isfinite(f) & (f == np.round(f))
        if not whole.all():
            face = int(np.flatnonzero(~whole.all(axis=1))[0])
            raise MeshError(
                f"face indices must be whole numbers; face {face} is {f[face].tolist()}"
            )
    if f.shape[1] != 3:
        if f.shape[0] == 3 and f.shape[1] > 3:
            raise MeshError(
                f"faces have shape {f.shape}: three rows of {f.shape[1]} indices, one "
                "column per face; faces are one row per face, (m, 3): pass faces.T"
            )
        if not polygons:
            raise MeshError(
                f"faces have shape {f.shape}: polygons of {f.shape[1]} vertices; a Mesh "
                "holds triangles (as_mesh and repair_mesh split polygons into triangles)"
            )
    f = f.astype(np.int64)
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise MeshError(
            f"{_plural(int(bad.sum()), 'vertex')} have NaN or infinite coordinates (first: "
            f"vertex {int(np.flatnonzero(bad)[0])}); fix the coordinates in the source "
            "application and export again"
        )
    n = len(v)
    out = (f < 0) | (f >= n)
    if out.any():
        face = int(np.flatnonzero(out.any(axis=1))[0])
        cause = "a file cut short or damaged, or arrays of two meshes"
        if f.min() >= 1 and f.max() == n:  # every index one too large at most
            cause = "faces numbered from 1 as in OBJ files, where 0 is the first vertex: subtract 1"
        raise MeshError(
            f"face {face} refers to vertex {int(f[face][out[face]][0])}, which does not exist "
            f"(the mesh has {_plural(n, 'vertex')}); faces and vertices do not belong "
            f"together ({cause})"
        )
    note = ""
    if f.shape[1] > 3:
        p = f.shape[1]
        kind = "quad" if p == 4 else f"polygon of {p} vertices"
        note = (
            f"Split {_plural(len(f), kind)} into {_plural(len(f) * (p - 2), 'triangle')} "
            "(fanned from each one's first vertex)."
        )
        f = np.stack([f[:, [0, i, i + 1]] for i in range(1, p - 1)], axis=1).reshape(-1, 3)
    return v, f, note


class Mesh:
    """A validated triangle mesh; a :class:`MeshError` for no faces, coordinates not
    finite, indices out of range, or a face that repeats a vertex or has zero area.
    ``file_map`` is only for a :attr:`solver_mesh` (:attr:`file_to_mesh`);
    ``merged_into``: :attr:`merged_into`."""

    def __init__(
        self,
        vertices,
        faces,
        report: MeshReport | None = None,
        file_map: np.ndarray | None = None,
        merged_into: np.ndarray | None = None,
    ):
        v, f, _ = checked_arrays(vertices, faces)
        repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2])
        if repeated.any():
            raise MeshError(
                f"{_plural(int(repeated.sum()), 'face')} repeat a vertex (first: face "
                f"{int(np.flatnonzero(repeated)[0])}); load with repair=True to drop them"
            )
        self._vertices = v
        self._faces = f
        self._vertices.setflags(write=False)
        self._faces.setflags(write=False)
        areas = self.face_areas
        scale = max(self.bounding_box_diagonal, np.finfo(float).tiny)
        degenerate = areas <= 1e-14 * scale**2
        if degenerate.any():
            raise MeshError(
                f"{_plural(int(degenerate.sum()), 'face')} have zero area (first: face "
                f"{int(np.flatnonzero(degenerate)[0])}); loading with repair (load_mesh or "
                "as_mesh with repair=True, the default) collapses them"
            )
        self.report = report if report is not None else MeshReport()
        self._file_map = None
        n = len(v)
        if file_map is not None:
            fm = np.array(file_map, dtype=np.int64, copy=True).reshape(-1)
            if fm.size and (fm.min() < -1 or fm.max() >= n):
                raise MeshError("file_map refers to vertices the mesh does not have")
            if not np.bincount(fm[fm >= 0], minlength=n).all():
                raise MeshError("file_map leaves a mesh vertex without a vertex of the file")
            if not (len(fm) == n and np.array_equal(fm, np.arange(n))):
                fm.setflags(write=False)
                self._file_map = fm
        self._merged = None
        if merged_into is not None:
            mi = np.array(merged_into, dtype=np.int64).reshape(-1)
            if mi.shape != (n,) or (n and (mi.min() < 0 or mi.max() >= n)):
                raise MeshError(f"merged_into must hold one vertex index per vertex ({n})")
            if np.any(mi[mi] != mi):
                raise MeshError("merged_into must name vertices that are not merged themselves")
            if not np.array_equal(mi, np.arange(n)):
                mi.setflags(write=False)
                self._merged = mi
        self._input: Mesh | None = None

    # ------------------------------------------------------------------ basics
    @property
    def vertices(self) -> np.ndarray:
        """(n, 3) float64 vertex positions (read-only)."""
        return self._vertices

    @property
    def faces(self) -> np.ndarray:
        """(m, 3) int64 triangle vertex indices (read-only)."""
        return self._faces

    @property
    def n_vertices(self) -> int:
        return int(self._vertices.shape[0])

    @property
    def n_faces(self) -> int:
        return int(self._faces.shape[0])

    def __repr__(self) -> str:
        return f"Mesh(n_vertices={self.n_vertices}, n_faces={self.n_faces})"

    # ------------------------------------------------------- the input numbering
    @property
    def merged_into(self) -> np.ndarray:
        """(n,) int64: each vertex's vertex it was merged into (a duplicate, or the end of
        a collapsed zero-area face), whose values it takes; itself where none."""
        return np.arange(self.n_vertices) if self._merged is None else self._merged

    @cached_property
    def _in_face(self) -> np.ndarray:
        used = np.zeros(self.n_vertices, dtype=bool)
        used[self._faces.ravel()] = True
        used.setflags(write=False)
        return used

    @cached_property
    def unused(self) -> np.ndarray:
        """(u,) int64, ascending: the vertices without a value (NaN results), which no face
        uses and which are not merged into one that a face uses."""
        out = np.flatnonzero(~self._in_face[self.merged_into])
        out.setflags(write=False)
        return out

    @cached_property
    def solver_mesh(self) -> Mesh:
        """The mesh the solvers work on: this one's vertices that faces use, in their
        order (the mesh itself where all are used and none merged), with the maps back."""
        if self._file_map is not None or (self._merged is None and self._in_face.all()):
            return self
        rep = np.flatnonzero(self._in_face)
        compact = np.full(self.n_vertices, -1, dtype=np.int64)
        compact[rep] = np.arange(len(rep))
        solver = Mesh(
            self._vertices[rep],
            compact[self._faces],
            report=self.report,
            file_map=compact[self.merged_into],
        )
        rep.setflags(write=False)
        solver.__dict__["file_vertices"] = rep  # the input's vertex of each
        solver._input = self
        return solver

    @property
    def input_mesh(self) -> Mesh:
        """The mesh a :attr:`solver_mesh` was made from; any other mesh itself."""
        return self._input if self._input is not None else self

    # --------------------------------------------------- the file's numbering
    @property
    def file_map(self) -> np.ndarray | None:
        """:attr:`file_to_mesh`, or None where the numbering is the file's (identity):
        pass it as ``file_map`` to a new Mesh with the same vertices in the same order."""
        return self._file_map

    @property
    def renumbered(self) -> bool:
        """True if vertex i of this mesh is not always vertex i of the file."""
        return self._file_map is not None

    @property
    def n_file_vertices(self) -> int:
        """Number of vertices in the file (used or not)."""
        return self.n_vertices if self._file_map is None else len(self._file_map)

    @property
    def file_to_mesh(self) -> np.ndarray:
        """(n_file,) int64: each file vertex's mesh vertex, -1 where no face uses it
        (merged duplicates share their mesh vertex)."""
        if self._file_map is None:
            return np.arange(self.n_vertices)
        return self._file_map

    @cached_property
    def file_vertices(self) -> np.ndarray:
        """(n,) int64: each mesh vertex's index in the file (for merged duplicates the
        first of them)."""
        fm = self._file_map
        if fm is None:
            return np.arange(self.n_vertices)
        out = np.full(self.n_vertices, len(fm), dtype=np.int64)
        used = np.flatnonzero(fm >= 0)
        np.minimum.at(out, fm[used], used)
        out.setflags(write=False)
        return out

    def file_vertex(self, index: int) -> int:
        """The input's number of vertex ``index`` of a solver mesh (the vertex a face
        uses, of merged duplicates); ``index`` itself for any other mesh."""
        index = int(index)
        if not 0 <= index < self.n_vertices:
            raise MeshError(
                f"mesh vertex {index} does not exist (the mesh has "
                f"{_plural(self.n_vertices, 'vertex')})"
            )
        return int(self.file_vertices[index])

    def mesh_vertex(self, file_index: int) -> int:
        """The mesh vertex of vertex ``file_index`` of the file; a :class:`MeshError` if
        the file has no such vertex or no face uses it."""
        file_index = int(file_index)
        n = self.n_file_vertices
        if not 0 <= file_index < n:
            raise MeshError(
                f"vertex {file_index} is not in the file (it has {_plural(n, 'vertex')}, "
                f"numbered 0 to {n - 1})"
            )
        if self._file_map is None:
            if self._merged is not None or not self._in_face.all():
                if not self._in_face[self.merged_into[file_index]]:
                    raise MeshError(_unused_words(file_index))
            return file_index
        mesh_index = int(self._file_map[file_index])
        if mesh_index < 0:
            raise MeshError(_unused_words(file_index))
        return mesh_index

    def to_file_field(self, values) -> np.ndarray:
        """A per-vertex array (n, ...) in the file's numbering (n_file, ...): float, NaN
        at file vertices no face uses; merged duplicates share their value."""
        a = np.asarray(values)
        if a.shape[:1] != (self.n_vertices,):
            raise ValueError(
                f"expected {self.n_vertices} values (one per mesh vertex), got shape {a.shape}"
            )
        if self._file_map is None:
            return a.astype(np.float64) if not np.issubdtype(a.dtype, np.floating) else a
        fm = self._file_map
        out = np.full((len(fm), *a.shape[1:]), np.nan, dtype=np.result_type(a.dtype, np.float64))
        used = fm >= 0
        out[used] = a[fm[used]]
        return out

    @cached_property
    def hash(self) -> str:
        """SHA-256 of vertices and faces: identifies the exact geometry."""
        h = hashlib.sha256()
        h.update(np.ascontiguousarray(self._vertices).tobytes())
        h.update(np.ascontiguousarray(self._faces).tobytes())
        return h.hexdigest()

    @cached_property
    def face_normals_unnormalized(self) -> np.ndarray:
        """(m, 3) N_T = (x1 - x0) x (x2 - x0); its length is twice the face area."""
        v, f = self._vertices, self._faces
        return np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])

    @cached_property
    def face_areas(self) -> np.ndarray:
        """(m,) triangle areas."""
        return 0.5 * np.linalg.norm(self.face_normals_unnormalized, axis=1)

    @cached_property
    def face_quality(self) -> np.ndarray:
        """(m,) :func:`triangle_quality` of each face (1 equilateral, near 0 a sliver)."""
        return triangle_quality(self._vertices, self._faces)

    @cached_property
    def bounding_box_diagonal(self) -> float:
        """The diagonal of the bounding box of the vertices that faces use."""
        v = self._vertices
        if not self._in_face.all():
            v = v[self._in_face]
        return float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))

    @property
    def total_area(self) -> float:
        return float(self.face_areas.sum())

    # ---------------------------------------------------------------- topology
    @cached_property
    def _edge_data(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unique undirected edges (E, 2) sorted, face-edge -> edge map (m, 3), counts (E,)."""
        f = self._faces
        # half-edge k of face t goes from f[t, k] to f[t, (k + 1) % 3]
        he = np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)
        key = np.sort(he, axis=1)
        edges, inverse, counts = _unique_index_rows(key, return_inverse=True, return_counts=True)
        return edges, inverse.reshape(-1, 3), counts

    @property
    def edges(self) -> np.ndarray:
        """(E, 2) unique undirected edges, each row sorted ascending."""
        return self._edge_data[0]

    @property
    def face_edges(self) -> np.ndarray:
        """(m, 3) index into :attr:`edges` of face t's edge from corner k to corner k+1."""
        return self._edge_data[1]

    @property
    def edge_face_counts(self) -> np.ndarray:
        """(E,) number of faces incident to each edge (1 on a boundary)."""
        return self._edge_data[2]

    @cached_property
    def n_components(self) -> int:
        """Number of connected components (through faces)."""
        return int(self.component_labels.max()) + 1

    @cached_property
    def n_face_components(self) -> int:
        """Number of parts whose faces are connected through shared edges: more than
        :attr:`n_components` where parts meet only at vertices (a part meeting the rest
        at a single vertex can rotate about it: three more zero modes of the shells)."""
        # faces joined through each edge's consecutive faces (int32 throughout: the
        # graph's arrays are the load's largest temporaries)
        F = self.n_faces
        fe = self.face_edges.ravel()
        order = np.argsort(fe, kind="stable").astype(np.int32)
        shared = fe[order[1:]] == fe[order[:-1]]
        a, b = order[:-1][shared] // 3, order[1:][shared] // 3
        del order, shared
        graph = sp.csr_matrix((np.ones(len(a), dtype=np.float32), (a, b)), shape=(F, F))
        del a, b
        return int(connected_components(graph, directed=False)[0])

    @cached_property
    def component_labels(self) -> np.ndarray:
        """(n,) connected-component label of each vertex, in the order of their first
        vertices; -1 for :attr:`unused` vertices, a merged one's that of its vertex."""
        e = self.edges
        n = self.n_vertices
        adj = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
        _, labels = connected_components(adj, directed=False)
        if self._merged is None and self._in_face.all():
            return labels
        used = self._in_face
        _, first, inverse = np.unique(labels[used], return_index=True, return_inverse=True)
        rank = np.empty(len(first), dtype=np.int64)
        rank[np.argsort(first, kind="stable")] = np.arange(len(first))
        out = np.full(n, -1, dtype=np.int64)
        out[used] = rank[inverse.reshape(-1)]
        return np.where(used[self.merged_into], out[self.merged_into], -1)

    @property
    def n_boundary_edges(self) -> int:
        return int((self.edge_face_counts == 1).sum())

    @property
    def n_nonmanifold_edges(self) -> int:
        return int((self.edge_face_counts > 2).sum())

    @property
    def is_edge_manifold(self) -> bool:
        """True if every edge has one or two incident faces."""
        return self.n_nonmanifold_edges == 0

    @cached_property
    def is_consistently_oriented(self) -> bool:
        """True if every interior edge is traversed in opposite directions by its two faces."""
        f = self._faces
        he = np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)
        _, counts = _unique_index_rows(he, return_counts=True)
        return bool(counts.max() == 1)

    def shell_problem(self) -> str | None:
        """Why the Discrete Shells and E_D^N operators cannot run here, or None."""
        if not self.is_edge_manifold:
            return (
                f"the mesh has {_plural(self.n_nonmanifold_edges, 'edge')} shared by more "
                "than two faces (non-manifold); dihedral angles and vertex normals are not "
                "defined there. Split or remove those faces; the Laplacian still works."
            )
        if not self.is_consistently_oriented:
            return (
                "the faces are not consistently oriented (the surface may be non-orientable); "
                "normals and dihedral angles are ambiguous. Load with repair=True to re-orient "
                "it; the Laplacian still works."
            )
        return None


def _unique_index_rows(rows: np.ndarray, **kwargs):
    """``np.unique(rows, axis=0, **kwargs)`` for non-negative integer rows, through one
    int64 key per row: a 1-D sort, much faster than numpy's row-wise unique."""
    rows = np.asarray(rows, dtype=np.int64)
    base = int(rows.max(initial=0)) + 1
    if rows.size == 0 or base ** rows.shape[1] >= 2**62:
        return np.unique(rows, axis=0, **kwargs)
    key = np.zeros(len(rows), dtype=np.int64)
    for c in range(rows.shape[1]):
        key = key * base + rows[:, c]
    with_index = kwargs.pop("return_index", False)
    _, first, *rest = np.unique(key, return_index=True, **kwargs)  # unique rows: rows[first]
    out = (rows[first], first, *rest) if with_index else (rows[first], *rest)
    return out if len(out) > 1 else out[0]


def shape_summary(mesh: Mesh) -> str:
    """The report's first sentence: vertices, faces, components, boundary, non-manifold
    edges, and parts joined to the rest only at vertices."""
    unused = len(mesh.unused)
    summary = (
        f"{_plural(mesh.n_vertices, 'vertex')}"
        + (f" ({unused} used by no face)" if unused else "")
        + f", {_plural(mesh.n_faces, 'face')}, {_plural(mesh.n_components, 'component')}"
    )
    if mesh.n_boundary_edges:
        summary += f", {_plural(mesh.n_boundary_edges, 'boundary edge')}"
    elif mesh.is_edge_manifold:
        summary += ", closed"
    else:  # no boundary, but not a closed surface either
        summary += ", no boundary edges"
    if not mesh.is_edge_manifold:
        summary += f", {_plural(mesh.n_nonmanifold_edges, 'non-manifold edge')}"
    hinged = mesh.n_face_components - mesh.n_components
    if hinged > 0:
        summary += (
            f", {_plural(hinged, 'part')} joined to the rest only at a vertex (free to "
            "turn about it: 3 more zero modes each for the 3D shells)"
        )
    return summary + "."


def remove_unused(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """``(compact, kept)``: a copy of ``mesh`` of its vertices that faces use, vertex i
    being ``mesh``'s vertex ``kept[i]`` (ascending), so ``values[kept]`` moves values."""
    solver = mesh.solver_mesh
    kept = np.array(solver.file_vertices if solver is not mesh else np.arange(mesh.n_vertices))
    compact = Mesh(solver.vertices, solver.faces, report=mesh.report)
    return compact, kept
