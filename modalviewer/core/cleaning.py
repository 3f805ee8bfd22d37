"""Load-time repair of triangle arrays: :func:`repair_mesh` merges duplicate vertices,
collapses faces of zero area, drops repeated faces and orients the faces consistently,
keeping every input vertex in its place, and says what it did in plain words."""

from __future__ import annotations

from collections import deque

import numpy as np
import scipy.sparse as sp

from .mesh import (
    Mesh,
    MeshError,
    MeshReport,
    _plural,
    _unique_index_rows,
    checked_arrays,
    shape_summary,
    triangle_areas,
)

_LISTED = 10  # vertex numbers a report lists before "and N more"


def _listing(items: list[str], total: int) -> str:  # 'vertex 3', 'vertices 3, 7 and 2 more'
    text = ", ".join(items)
    if total > len(items):
        text += f" and {total - len(items)} more"
    return ("vertex " if total == 1 else "vertices ") + text


def _merge_duplicate_vertices(v: np.ndarray, f: np.ndarray, tol: float):
    """Vertices within ``tol`` of each other merged into the first of them: (vertices,
    faces, how many merged, each file vertex's new index, each new vertex's file
    index).  Only vertices that faces use are merged: one no face uses stays apart."""
    key = np.round(v / tol).astype(np.int64) if tol > 0 else v
    in_face = np.zeros(len(v), dtype=bool)
    in_face[f.ravel()] = True
    key = np.column_stack([key, np.where(in_face, -1, np.arange(len(v)))])
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    order = np.argsort(first)  # keep the original order of first occurrences
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    kept = first[order]
    return v[kept], rank[inverse][f], len(v) - len(kept), rank[inverse], kept


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (r, 3) arrays (np.cross has a large fixed cost per call)."""
    return np.column_stack(
        [
            a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0],
        ]
    )


def _collapsible(p: int, q: int, v, f, topo, min_area: float) -> bool:
    """Whether merging vertex p into q keeps the surface a manifold and turns no face
    around p upside down (``topo``: :func:`_topology`)."""
    fi, fp, ni, nptr, on_boundary, adj = topo
    around_p = fi[fp[p] : fp[p + 1]]
    with_q = (f[around_p] == q).any(axis=1)
    opposite = set(f[around_p[with_q]].ravel().tolist()) - {p, q}
    nbrs_p, nbrs_q = ni[nptr[p] : nptr[p + 1]], ni[nptr[q] : nptr[q + 1]]
    if set(nbrs_p.tolist()) & set(nbrs_q.tolist()) != opposite:
        return False  # the collapse would glue two sheets together
    if on_boundary[p] and on_boundary[q] and adj[p, q] == 2:
        return False  # an inside edge between two boundary vertices: a pinch
    rest = f[around_p[~with_q]]
    if len(rest):
        before = _cross_rows(v[rest[:, 1]] - v[rest[:, 0]], v[rest[:, 2]] - v[rest[:, 0]])
        g = np.where(rest == p, q, rest)
        after = _cross_rows(v[g[:, 1]] - v[g[:, 0]], v[g[:, 2]] - v[g[:, 0]])
        big = (before * before).sum(axis=1) > (2 * min_area) ** 2
        if np.any((before * after).sum(axis=1)[big] <= 0):
            return False  # a neighbouring face would turn over
    return True


def _repair_zero_area(v, f, min_area: float, diag: float, report: MeshReport, max_rounds=100):
    """Remove every face of area at most ``min_area`` without opening holes, in rounds
    of non-adjacent changes until none is left or none can be made: flip its longest
    edge where the apex lies a tenth to nine tenths along it (a remesh's T-junction: no
    vertex moves); else merge the apex into the nearer end of that edge, or collapse its
    other edges, shortest first, where the surface stays a manifold and no face turns
    over (:func:`_collapsible`); a face whose longest edge is on the boundary is removed;
    one that none of these can remove is dropped.  Says each in ``report``; returns
    (faces, (n,) vertex each vertex was merged into).
    """
    n = len(v)
    f = f.copy()
    merged_into = np.arange(n)
    collapsed, flipped, dropped, largest = 0, 0, 0, 0.0
    for _ in range(max_rounds):
        zero = np.flatnonzero(triangle_areas(v, f) <= min_area)
        if zero.size == 0:
            break
        zf = f[zero]
        lengths = np.stack(
            [np.linalg.norm(v[zf[:, (c + 1) % 3]] - v[zf[:, c]], axis=1) for c in range(3)],
            axis=1,
        )  # edge c runs from corner c to corner c + 1
        rows = np.arange(len(zf))
        order = np.argsort(lengths.min(axis=1), kind="stable")  # shortest edge first

        topo = _topology(f, n)

        # A zero-area face along the boundary (its longest edge on no other face) is
        # removed: the boundary then runs through its apex, along the same line.
        lo = np.argmax(lengths, axis=1)
        u, w = zf[rows, lo], zf[rows, (lo + 1) % 3]
        along_boundary = np.asarray(topo[5][u, w]).ravel() == 1  # faces on the edge
        drop = np.zeros(len(f), dtype=bool)
        drop[zero[along_boundary]] = True

        locked = np.zeros(n, dtype=bool)
        locked[f[drop].ravel()] = True
        remap = np.arange(n)
        merged = 0
        flipped_before = flipped
        for i in order:
            corners = zf[i]
            if along_boundary[i] or locked[corners].any():
                continue  # a neighbour changed in this round: the next round sees it
            # an apex well inside the longest edge: flip that edge (nothing moves)
            a_, b_, x_ = (int(corners[(lo[i] + c) % 3]) for c in range(3))
            ab = v[b_] - v[a_]
            t = float(np.dot(v[x_] - v[a_], ab) / max(np.dot(ab, ab), np.finfo(float).tiny))
            if 0.1 <= t <= 0.9 and _flip(zero[i], a_, b_, x_, v, f, topo, min_area, locked):
                flipped += 1
                continue
            # else collapse an edge of this face, shortest first, either way round; on
            # the shortest, the apex into the nearer end first
            tries = []
            for e in np.argsort(lengths[i], kind="stable"):
                u, w = int(corners[e]), int(corners[(e + 1) % 3])
                tries += [(w, u), (u, w)] if w == x_ and not tries else [(u, w), (w, u)]
            move = _collapse(tries, v, f, topo, min_area, locked, remap)
            if move is not None:
                largest = max(largest, move)
                merged += 1
        if merged == 0 and flipped == flipped_before and not drop.any():
            break
        collapsed += merged
        dropped += int(drop.sum())
        merged_into = remap[merged_into]
        f = remap[f[~drop]]
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    left = int((triangle_areas(v, f) <= min_area).sum()) if len(f) else 0
    if flipped:
        report.add(
            f"Flipped the longest edge of {_plural(flipped, 'degenerate (zero-area) face')}"
            " (a vertex lying inside that edge: the two faces on it became two faces "
            "with area; no vertex moved, no holes opened)."
        )
    if collapsed:
        report.add(
            f"Collapsed {_plural(collapsed, 'degenerate (zero-area) face')} (merged the "
            "two vertices of each one's shortest edge, moving none more than "
            f"{largest / diag:.1e} of the bounding-box diagonal; no holes opened)."
        )
    if dropped:
        report.add(
            f"Removed {_plural(dropped, 'degenerate (zero-area) face')} lying along the "
            "boundary (the boundary keeps its shape)."
        )
    if left:
        f = f[triangle_areas(v, f) > min_area]
        report.add(
            f"Removed {_plural(left, 'degenerate (zero-area) face')} that could not be "
            "flipped or collapsed without tearing or folding the surface (this can "
            "leave holes)."
        )
    return f, merged_into


def _topology(f: np.ndarray, n: int):
    """(fi, fp, ni, nptr, on_boundary, adj): vertex -> faces and vertex -> neighbours
    (CSR indices and pointers), the boundary vertices and the faces per edge (n, n)."""
    m = len(f)
    vf = sp.csr_matrix(
        (np.ones(3 * m, dtype=np.int8), (f.ravel(), np.repeat(np.arange(m), 3))),
        shape=(n, m),
    )
    he = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    adj = sp.csr_matrix(
        (np.ones(len(he), dtype=np.int32), (he.min(axis=1), he.max(axis=1))), shape=(n, n)
    )
    adj = (adj + adj.T).tocsr()
    on_boundary = np.zeros(n, dtype=bool)
    bi, bj = (adj == 1).nonzero()
    on_boundary[bi] = on_boundary[bj] = True
    return vf.indices, vf.indptr, adj.indices, adj.indptr, on_boundary, adj


def _lock(locked: np.ndarray, topo, vertices) -> None:
    """Mark ``vertices`` and their neighbours as changed in this round."""
    ni, nptr = topo[2], topo[3]
    for w in vertices:
        locked[w] = True
        locked[ni[nptr[w] : nptr[w + 1]]] = True


def _flip(t: int, a: int, b: int, x: int, v, f, topo, min_area: float, locked) -> bool:
    """Flip the edge ab of the zero-area face t = (a, b, x) in place, trading it with the
    face across it for the edge xd (d that face's third vertex), where the far corner is
    not locked and the surface stays a manifold with both new faces of area facing the
    way the old neighbour did; whether it did."""
    fi, fp, ni, nptr = topo[:4]
    around_a = fi[fp[a] : fp[a + 1]]
    across = [int(g) for g in around_a if g != t and b in f[g]]
    if len(across) != 1:
        return False
    g = across[0]
    k = int(np.flatnonzero(f[g] == b)[0])
    if f[g][(k + 1) % 3] != a:  # the neighbour must run b -> a
        return False
    d = int(f[g][(k + 2) % 3])
    if d == x or x in ni[nptr[d] : nptr[d + 1]] or locked[d]:
        return False
    old = _cross_rows(v[[a]] - v[[b]], v[[d]] - v[[b]])[0]
    new = _cross_rows(v[[d, b]] - v[[a, d]], v[[x, x]] - v[[a, d]])
    if np.any(0.5 * np.linalg.norm(new, axis=1) <= min_area) or np.any(new @ old <= 0):
        return False
    f[t] = (a, d, x)
    f[g] = (d, b, x)
    _lock(locked, topo, (a, b, x, d))
    return True


def _collapse(tries, v, f, topo, min_area: float, locked, remap) -> float | None:
    """Merge the first vertex pair (p, q) of ``tries`` that is unlocked and
    :func:`_collapsible` (p into q, in ``remap``); the distance p moves, or None."""
    for p, q in tries:
        if locked[p] or locked[q] or not _collapsible(p, q, v, f, topo, min_area):
            continue
        remap[p] = q
        _lock(locked, topo, (p, q))
        return float(np.linalg.norm(v[p] - v[q]))
    return None


def _orient_faces(f: np.ndarray) -> tuple[np.ndarray, int, bool]:
    """Flip faces so neighbours across manifold edges agree (BFS per component): (faces,
    number flipped, orientable)."""
    m = len(f)
    he = np.stack([f, np.roll(f, -1, axis=1)], axis=2).reshape(-1, 2)
    key = np.sort(he, axis=1)
    _, inv, counts = _unique_index_rows(key, return_inverse=True, return_counts=True)
    inv = inv.reshape(-1)
    face_of = np.repeat(np.arange(m), 3)
    order = np.argsort(inv, kind="stable")
    starts = np.concatenate([[0], np.cumsum(counts)])
    # neighbours only across manifold edges (exactly two faces)
    manifold = np.flatnonzero(counts == 2)
    if len(manifold) == 0:
        return f, 0, True
    pa = np.stack([order[starts[manifold]], order[starts[manifold] + 1]], axis=1)
    fa, fb = face_of[pa[:, 0]], face_of[pa[:, 1]]
    same_dir = np.all(he[pa[:, 0]] == he[pa[:, 1]], axis=1)  # same direction: inconsistent
    if not same_dir.any():  # already consistent (the common case): nothing to walk
        return f, 0, True
    nbrs: list[list[tuple[int, bool]]] = [[] for _ in range(m)]
    for x, y, s in zip(fa.tolist(), fb.tolist(), same_dir.tolist(), strict=True):
        nbrs[x].append((y, s))
        nbrs[y].append((x, s))
    flip = np.zeros(m, dtype=bool)
    seen = np.zeros(m, dtype=bool)
    patch = np.zeros(m, dtype=np.int64)
    orientable = True
    for seed in range(m):
        if seen[seed]:
            continue
        seen[seed] = True
        queue = deque([seed])
        while queue:
            t = queue.popleft()
            patch[t] = seed
            for u, s in nbrs[t]:
                want = flip[t] ^ s
                if not seen[u]:
                    seen[u] = True
                    flip[u] = want
                    queue.append(u)
                elif flip[u] != want:
                    orientable = False
    # per patch, keep the majority orientation (flip the fewest faces)
    flipped_per_patch = np.bincount(patch, flip, minlength=m)
    size_per_patch = np.bincount(patch, minlength=m)
    invert = flipped_per_patch > size_per_patch / 2
    flip ^= invert[patch]
    out = f.copy()
    out[flip] = out[flip][:, ::-1]
    return out, int(flip.sum()), orientable


def repair_mesh(vertices, faces, source: str = "", merge_tolerance: float = 1e-10):
    """A valid :class:`Mesh` of raw arrays, ``mesh.report`` saying every change: vertices
    closer than ``merge_tolerance`` times the bounding-box diagonal merged, faces that
    repeat a vertex or another face dropped, faces of zero area flipped or collapsed,
    the orientation made consistent where possible.  Only the faces change: vertex i
    stays row i of ``vertices``."""
    report = MeshReport(source=source)
    v, f, split = checked_arrays(vertices, faces, polygons=True)
    if split:
        report.add(split)
    diag = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    if diag == 0:
        raise MeshError("all vertices coincide: the mesh has no extent")

    n_file = len(v)
    v_input = v
    v, f, merged, file_map, rep = _merge_duplicate_vertices(v, f, merge_tolerance * diag)
    if merged:  # rep: each merged group's first vertex
        dup = np.flatnonzero(rep[file_map] != np.arange(n_file))
        pairs = [f"{int(i)} into {int(rep[file_map[i]])}" for i in dup[:_LISTED]]
        report.add(
            f"Merged {_plural(merged, 'duplicate vertex')} ("
            + _listing(pairs, len(dup))
            + ", counting from 0; each takes the values of the vertex it was merged into)."
        )

    repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 0] == f[:, 2])
    if repeated.any():
        f = f[~repeated]
        report.add(f"Removed {_plural(int(repeated.sum()), 'face')} that repeat a vertex.")
    if len(f):
        _, keep = _unique_index_rows(np.sort(f, axis=1), return_index=True)
        if len(keep) < len(f):
            report.add(f"Removed {_plural(len(f) - len(keep), 'duplicate face')}.")
            f = f[np.sort(keep)]
    min_area = 1e-14 * diag**2
    if len(f) and np.any(triangle_areas(v, f) <= min_area):
        f, merged_into = _repair_zero_area(v, f, min_area, diag, report)
        file_map = merged_into[file_map]
    if len(f) == 0:
        raise MeshError("no faces are left after removing degenerate ones: not a surface")

    used = np.zeros(len(v), dtype=bool)
    used[f.ravel()] = True
    if not used.all():
        remap = np.where(used, np.cumsum(used) - 1, -1)
        file_map = remap[file_map]
        v, f, rep = v[used], remap[f], rep[used]
    unreferenced = np.flatnonzero(file_map < 0)  # merged ones are said above
    if len(unreferenced):
        them = "it has" if len(unreferenced) == 1 else "they have"
        report.add(
            f"{_plural(len(unreferenced), 'vertex').capitalize()} used by no face ("
            + _listing([str(int(i)) for i in unreferenced[:_LISTED]], len(unreferenced))
            + f", counting from 0): {them} no value (NaN) in the results; vertex numbers "
            "stay the input's (mesh.unused lists them)."
        )

    f, flipped, orientable = _orient_faces(f)
    if flipped:
        report.add(f"Flipped {_plural(flipped, 'face')} to make the orientation consistent.")
    if not orientable:
        report.add("The surface is not orientable, so some faces disagree in orientation.")

    # the input's numbering: every input vertex in its place, the faces on the vertex
    # of each merged group that has the group's coordinates
    merged_into = np.where(file_map >= 0, rep[np.maximum(file_map, 0)], np.arange(n_file))
    mesh = Mesh(v_input, rep[f], report=report, merged_into=merged_into)
    report.messages.insert(0, shape_summary(mesh))
    problem = mesh.shell_problem()
    if problem:
        report.add("Shells and E_D^N cannot run: " + problem)
    return mesh
