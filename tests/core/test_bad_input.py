"""A corpus of messy files: each gives a correct result after a reported repair, or a
clear MeshError naming the problem; never a traceback, a hang or NaN."""

import struct

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import grid_plate, icosphere


def _obj(path, v, faces_lines):
    lines = [f"v {a:.17g} {b:.17g} {c:.17g}" for a, b, c in np.asarray(v, dtype=float)]
    lines += faces_lines
    path.write_text("\n".join(lines) + "\n")
    return path


def _tri_lines(f):
    return ["f " + " ".join(str(i + 1) for i in t) for t in f]


def _sphere_obj(tmp_path, name="s.obj", scale=1.0):
    s = icosphere(2)
    return _obj(tmp_path / name, s.vertices * scale, _tri_lines(s.faces))


def _ply_strips(path):
    # a 2 x 1 quad strip as one triangle strip: vertices 0..5, strip 0 1 2 3 4 5
    v = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [2, 0, 0], [2, 1, 0]], float)
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 6\n"
        "property float x\nproperty float y\nproperty float z\n"
        "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
    )
    body = b"".join(struct.pack("<3f", *p) for p in v)
    body += struct.pack("<i", 6) + struct.pack("<6i", 0, 1, 2, 3, 4, 5)
    path.write_bytes(header.encode() + body)
    return path


def _cases(tmp_path):
    plate = grid_plate(6, 6)
    s = icosphere(2)
    n = plate.n_vertices
    yield "empty", (tmp_path / "e.obj").write_text("") or tmp_path / "e.obj", "error", "empty"
    rnd = tmp_path / "r.ply"
    rnd.write_bytes(np.random.default_rng(0).bytes(5000))
    yield "random bytes", rnd, "error", "r.ply"
    wrong = tmp_path / "mesh.xyz"
    wrong.write_text("1 2 3\n")
    yield "wrong extension", wrong, "error", "unsupported"
    full = _sphere_obj(tmp_path, "full.obj").read_text()
    trunc = tmp_path / "trunc.obj"
    trunc.write_text(full[: len(full) * 2 // 3].rsplit("\n", 1)[0] + "\nf 1 2 999\n")
    yield "truncated", trunc, "error", "truncated"
    nan = _obj(tmp_path / "nan.obj", [[0, 0, 0], [1, 0, np.nan], [0, 1, 0]], ["f 1 2 3"])
    yield "NaN", nan, "error", "NaN"
    inf = _obj(tmp_path / "inf.obj", [[0, 0, 0], [1, 0, np.inf], [0, 1, 0]], ["f 1 2 3"])
    yield "Inf", inf, "error", "NaN or infinite"
    yield "point cloud", _obj(tmp_path / "pc.obj", np.eye(3), []), "error", "point cloud"
    oor = _obj(tmp_path / "oor.obj", np.eye(3), ["f 1 2 7"])
    yield "out of range", oor, "error", "truncated"
    dup = _obj(
        tmp_path / "dup.obj",
        np.vstack([plate.vertices, plate.vertices]),
        _tri_lines(np.vstack([plate.faces, plate.faces + n])),
    )
    yield "duplicate vertices", dup, "ok", "Merged"
    unref = _obj(
        tmp_path / "unref.obj", np.vstack([plate.vertices, [[5, 5, 5]]]), _tri_lines(plate.faces)
    )
    yield "unreferenced", unref, "ok", ""
    v = np.vstack([plate.vertices, [[0.5, 0.5, 0.0]], [[0.5, 0.5 + 1e-13, 0.0]]])
    zero = _obj(tmp_path / "zero.obj", v, _tri_lines(np.vstack([plate.faces, [[0, 1, 2]]])))
    yield "zero-area", zero, "ok", "degenerate"
    needle_v = np.array(plate.vertices)
    needle_v[8] += [0.0, 1e-7, 0.0]
    yield "needle", _obj(tmp_path / "needle.obj", needle_v, _tri_lines(plate.faces)), "ok", ""
    nm_v = np.vstack([plate.vertices, [[0.5, 0.5, 1.0]]])
    nm = _obj(tmp_path / "nm.obj", nm_v, _tri_lines(np.vstack([plate.faces, [[0, 8, n]]])))
    yield "non-manifold edge", nm, "ok-laplacian", "non-manifold"
    two = np.vstack([s.vertices, s.vertices + [3, 0, 0]])
    bowtie = np.vstack([s.faces, s.faces + s.n_vertices])
    # glue the spheres at one vertex: non-manifold vertex
    bowtie[bowtie == s.n_vertices] = 0
    nmv = _obj(tmp_path / "nmv.obj", two, _tri_lines(bowtie))
    yield "non-manifold vertex", nmv, "ok", ""
    flipped = np.array(s.faces)
    flipped[::3] = flipped[::3, ::-1]
    yield "orientation", _obj(tmp_path / "o.obj", s.vertices, _tri_lines(flipped)), "ok", "Flipped"
    yield (
        "open boundary",
        _obj(tmp_path / "p.obj", plate.vertices, _tri_lines(plate.faces)),
        "ok",
        "",
    )
    comps = _obj(
        tmp_path / "c.obj",
        np.vstack([s.vertices, s.vertices + [4, 0, 0]]),
        _tri_lines(np.vstack([s.faces, s.faces + s.n_vertices])),
    )
    yield "components", comps, "ok", "2 components"
    quads = tmp_path / "q.obj"
    quads.write_text(
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 1.5 1.5 0\n"
        "f 1 2 3 4\nf 2 5 6 7 3\n"
    )
    yield "quads and polygons", quads, "ok", ""
    yield "single triangle", _obj(tmp_path / "t.obj", np.eye(3), ["f 1 2 3"]), "ok", ""
    yield "1e6 coordinates", _sphere_obj(tmp_path, "big.obj", 1e6), "ok", ""
    yield "1e-6 coordinates", _sphere_obj(tmp_path, "tiny.obj", 1e-6), "ok", ""
    yield "PLY triangle strips", _ply_strips(tmp_path / "strip.ply"), "ok", ""


def test_bad_input_corpus(tmp_path):
    outcomes = {}
    for name, path, expected, fragment in _cases(tmp_path):
        if expected == "error":
            with pytest.raises(mv.MeshError) as info:
                mv.load_mesh(path)
            message = str(info.value)
            assert fragment in message, (name, message)
            assert "\n" not in message and len(message) < 400, name
            outcomes[name] = message
            continue
        mesh = mv.load_mesh(path)
        assert fragment in str(mesh.report), (name, str(mesh.report))
        k = min(6, mesh.n_vertices)
        spec = mv.compute_spectrum(mesh, "laplacian", k=k)
        valued = np.setdiff1d(np.arange(mesh.n_vertices), mesh.unused)
        assert np.all(np.isfinite(spec.eigenvalues)), name
        assert np.all(np.isfinite(spec.modes[valued])), name
        assert np.all(np.isnan(spec.modes[mesh.unused])), name
        if expected == "ok-laplacian":
            with pytest.raises(mv.MeshError, match=fragment):
                mv.compute_spectrum(mesh, "shells", k=k)
        elif mesh.n_vertices > 10:
            she = mv.compute_spectrum(mesh, "shells", k=min(12, 3 * mesh.n_vertices))
            assert np.all(np.isfinite(she.eigenvalues)), name
        outcomes[name] = str(mesh.report)
    assert len(outcomes) == 22


def test_slivers_are_named_when_they_spoil_a_spectrum():
    from modalviewer.core.pipeline import sliver_hint
    from modalviewer.core.primitives import grid_plate

    plate = grid_plate(12, 12)
    assert sliver_hint(plate) == ""
    v = plate.vertices.copy()
    # squash one row of vertices onto its neighbour: a strip of needle triangles
    ys = np.unique(np.round(v[:, 1], 12))
    row = np.isclose(v[:, 1], ys[1])
    assert row.sum() >= 12
    v[row, 1] = ys[0] + 1e-9 * (ys[1] - ys[0])
    text = sliver_hint(mv.Mesh(v, plate.faces))
    assert "nearly degenerate triangles" in text and "face" in text


def test_a_surface_without_boundary_but_with_non_manifold_edges_is_not_called_closed(tmp_path):
    # two tetrahedra sharing an edge: no boundary edge, one edge of four faces
    tet = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]
    faces = tet + [(a if a < 2 else a + 2 for a in f) for f in tet]
    v = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (0, -1, 0), (0, 0, -1)]
    path = tmp_path / "two_tets.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in v] + [
        "f " + " ".join(str(i + 1) for i in f) for f in (tuple(f) for f in faces)
    ]
    path.write_text("\n".join(lines) + "\n")
    report = str(mv.load_mesh(path).report)
    assert "no boundary edges, 1 non-manifold edge" in report and "closed" not in report


def test_arrays_of_the_wrong_shape_or_numbered_from_one_say_so():
    # (n, 2) vertices were "the file contains no vertices"; faces numbered from 1 were
    # "a file cut short or damaged"
    spot = mv.load_mesh(mv.asset_path("spot.obj"))
    v, f = spot.vertices, spot.faces
    with pytest.raises(mv.MeshError, match=r"vertices must be an \(n, 3\) array .* \(2930, 2\)"):
        mv.as_mesh((v[:, :2], f))
    with pytest.raises(mv.MeshError, match="faces numbered from 1 as in OBJ files.*subtract 1"):
        mv.as_mesh((v, f + 1))
    with pytest.raises(mv.MeshError, match="cut short or damaged"):
        mv.as_mesh((v[:100], f))
