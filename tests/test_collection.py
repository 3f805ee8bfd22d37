"""Shape collections: ``run_batch`` on a local Dask cluster (threads, tiny meshes), the
store it writes, resuming, failures, ``similar``, and a batch killed midway."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer import collection as coll
from modalviewer.collection import runner
from modalviewer.core import pipeline, primitives

distributed = pytest.importorskip("distributed")

K = 8
ROOT = Path(__file__).resolve().parents[1]


def _write_obj(mesh, path: Path) -> None:
    with open(path, "w") as fh:
        for x, y, z in mesh.vertices:
            fh.write(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n")
        for a, b, c in mesh.faces + 1:
            fh.write(f"f {a} {b} {c}\n")


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def sources(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("meshes")
    torus = primitives.torus(14, 7)
    _write_obj(torus, folder / "torus.obj")
    moved = mv.Mesh(torus.vertices @ _rotation(0.7).T + [2.0, -1.0, 0.5], torus.faces)
    _write_obj(moved, folder / "torus_moved.obj")
    _write_obj(primitives.icosphere(1), folder / "sphere.obj")
    _write_obj(primitives.grid_plate(6, 5), folder / "plate.obj")
    fat = primitives.torus(14, 7, minor=0.5)
    _write_obj(fat, folder / "fat_torus.obj")
    rng = np.random.default_rng(3)  # no symmetry: every eigenvalue simple, modes unique
    sphere = primitives.icosphere(2)
    v = (
        sphere.vertices
        * [1.0, 1.3, 0.8]
        * (1.0 + 0.05 * rng.standard_normal((len(sphere.vertices), 1)))
    )
    _write_obj(mv.Mesh(v, sphere.faces), folder / "blob.obj")
    (folder / "broken.obj").write_text("v 0 0 0\nv 1 0\nf 1 2 3\n")
    return folder


@pytest.fixture(scope="module")
def client():
    with distributed.Client(
        processes=False, n_workers=1, threads_per_worker=2, dashboard_address=":0"
    ) as c:
        yield c


@pytest.fixture(scope="module")
def store(sources, client, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("store") / "store"
    summary = coll.run_batch([sources], path, "laplacian", K, ["hks", "vibration"], client=client)
    assert sorted(summary.computed) == [
        "blob",
        "fat_torus",
        "plate",
        "sphere",
        "torus",
        "torus_moved",
    ], summary
    return path


def _same_up_to_sign(a: np.ndarray, b: np.ndarray) -> None:
    a, b = a.reshape(-1, a.shape[-1]), b.reshape(-1, b.shape[-1])
    for j in range(a.shape[1]):
        sign = 1.0 if a[:, j] @ b[:, j] >= 0 else -1.0
        np.testing.assert_allclose(a[:, j], sign * b[:, j], atol=1e-10, rtol=0)


def _same_eigenspaces(a, b) -> None:
    """Equal projectors U U^T onto each cluster of equal eigenvalues (the last cluster
    only if the k modes hold all of it: it is cut off by k otherwise)."""
    lam = a.eigenvalues
    scale = max(abs(lam).max(), 1.0)
    cuts = [0, *(np.flatnonzero(np.diff(lam) > 1e-6 * scale) + 1)]
    for start, end in zip(cuts[:-1], cuts[1:], strict=True):
        ua = a.modes[..., start:end].reshape(-1, end - start)
        ub = b.modes[..., start:end].reshape(-1, end - start)
        np.testing.assert_allclose(ua @ ua.T, ub @ ub.T, atol=1e-9)


def test_store_spectra_equal_compute_spectrum(store, sources):
    c = mv.open_collection(store)
    assert c.names == ["blob", "fat_torus", "plate", "sphere", "torus", "torus_moved"]
    for name in c.names:
        mesh = mv.load_mesh(sources / f"{name}.obj")
        for op in ("laplacian", "shells"):
            direct = mv.compute_spectrum(mesh, op, K)
            stored = c.spectrum(name, None if op == "laplacian" else op)
            assert stored.operator == op and stored.mesh_hash == mesh.hash
            np.testing.assert_allclose(stored.eigenvalues, direct.eigenvalues, atol=1e-10)
            if name == "blob":  # simple eigenvalues: each mode unique up to sign
                _same_up_to_sign(stored.modes, direct.modes)
            else:  # symmetric shapes: the same eigenspaces
                _same_eigenspaces(stored, direct)
    mesh = mv.load_mesh(sources / "blob.obj")
    assert set(c.signatures("blob")) == {"hks", "vibration"}
    times, values = c.signatures("blob")["hks"]
    direct_times, direct_values = mv.signature(mv.compute_spectrum(mesh, "laplacian", K))
    np.testing.assert_allclose(times, direct_times, rtol=1e-10)
    np.testing.assert_allclose(values, direct_values, rtol=1e-8, atol=1e-12)
    d = c.descriptors
    assert d["shape_dna"].shape[0] == 6 and d["histogram.vibration"].shape == (6, 8, 32)
    np.testing.assert_allclose(d["histogram.hks"].sum(axis=2), 1.0, atol=1e-12)
    row = c.names.index("blob")
    np.testing.assert_allclose(d["area"][row], mesh.total_area)


def test_a_mesh_file_reads_with_numpy_alone(store):
    with np.load(store / "meshes" / "torus.npz") as data:
        entry = json.loads(str(data["entry"]))
        assert data["eigenvalues"].shape == (K,)
        assert data["modes"].shape == (entry["n_vertices"], K)
    index = json.loads((store / "index.json").read_text())
    assert set(index["entries"]) == {"blob", "fat_torus", "plate", "sphere", "torus", "torus_moved"}
    assert mv.load_spectrum(store / "meshes" / "torus.npz").k == K  # a spectrum file too


def test_a_broken_file_is_recorded_not_fatal(store):
    c = mv.open_collection(store)
    assert list(c.errors) == ["broken"]
    assert "broken.obj" in c.errors["broken"]
    record = json.loads((store / "errors" / "broken.json").read_text())
    assert record["source"].endswith("broken.obj")


def test_resume_recomputes_nothing(store, sources, client, monkeypatch):
    calls = []
    compute = pipeline.compute_spectrum

    def counted(*args):
        calls.append(args[1])
        return compute(*args)

    monkeypatch.setattr(pipeline, "compute_spectrum", counted)
    params = dict(operator="laplacian", k=K, signatures=["vibration", "hks"], client=client)
    summary = coll.run_batch([sources], store, **params)
    assert calls == [] and summary.computed == [] and len(summary.skipped) == 7
    assert summary.failed_before == ["broken"]
    # a recorded failure is not counted as if it were done without saying so
    assert summary.text().startswith(
        "0 computed, 7 already done (1 of them recorded failures, not tried again: "
        "--retry-failed), 0 failed, in "
    )
    # a touched file is read again, but its geometry hash says it is done
    os.utime(sources / "sphere.obj", ns=(time.time_ns(), time.time_ns()))
    summary = coll.run_batch([sources], store, **params)
    assert calls == [] and summary.computed == [] and "sphere" in summary.skipped
    # other parameters: another store (one holds one set of parameters)
    with pytest.raises(coll.CollectionError, match="other parameters need another store"):
        coll.run_batch([sources], store, "laplacian", K + 1, client=client)
    other = tmp = store.parent / "store_k6"
    summary = coll.run_batch([sources / "sphere.obj"], tmp, "laplacian", 6, client=client)
    assert calls == ["laplacian"] and summary.computed == ["sphere"]
    assert mv.open_collection(other).spectrum("sphere").k == 6


def test_similar_puts_the_shape_first_and_its_rigid_copy_second(store, sources):
    c = mv.open_collection(store)
    ranked = c.similar("torus", n=3)
    assert [name for name, _ in ranked[:2]] == ["torus", "torus_moved"]
    assert ranked[0][1] == 0.0 and ranked[1][1] < 1e-6 < ranked[2][1]
    from_file = c.similar(str(sources / "torus_moved.obj"), n=None)
    assert [name for name, _ in from_file[:2]] == ["torus_moved", "torus"]
    assert len(from_file) == 6
    # a mesh not in the store: its spectrum is computed with the store's parameters
    outside = primitives.torus(14, 7)
    outside = mv.Mesh(outside.vertices * 1.0 + [0.0, 0.0, 5.0], outside.faces)
    assert c.name_of(outside.hash) is None
    assert {name for name, _ in c.similar(outside, n=2)} == {"torus", "torus_moved"}


def test_cli_similar_and_batch_with_a_local_worker_process(store, sources, tmp_path):
    from modalviewer.cli import main

    assert main(["similar", str(store), str(sources / "torus.obj"), "-n", "2"]) == 0
    out = tmp_path / "cli_store"
    files = [str(sources / "sphere.obj"), str(sources / "plate.obj")]
    result = subprocess.run(
        [sys.executable, "-m", "modalviewer", "batch", *files, "-o", str(out), "-k", "6"]
        + ["--workers", "1"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert "2 computed" in result.stdout and "2/2 meshes" in result.stderr
    assert mv.open_collection(out).names == ["plate", "sphere"]


def test_cli_errors_are_one_line(sources, tmp_path, capsys):
    from modalviewer.cli import main

    assert main(["batch", str(tmp_path / "nothing"), "-o", str(tmp_path / "s")]) == 1
    assert main(["similar", str(tmp_path), "x.obj"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert all(line.startswith("modalviewer: error:") for line in err), err


def test_a_killed_batch_leaves_a_readable_store(tmp_path):
    folder = tmp_path / "many"
    folder.mkdir()
    rng = np.random.default_rng(1)
    sphere = primitives.icosphere(3)
    for i in range(12):
        v = sphere.vertices * (1.0 + 0.2 * rng.standard_normal(3))
        _write_obj(mv.Mesh(v, sphere.faces), folder / f"blob{i:02d}.obj")
    out = tmp_path / "store"
    command = [sys.executable, "-m", "modalviewer", "batch", str(folder), "-o", str(out)]
    command += ["--operator", "shells", "-k", "20", "--workers", "0"]
    process = subprocess.Popen(
        command, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.time() + 120
    while time.time() < deadline and not list((out / "meshes").glob("*.npz")):
        time.sleep(0.01)
    process.send_signal(signal.SIGKILL)
    process.wait()
    c = mv.open_collection(out)  # no index.json yet: rebuilt from the files
    assert 1 <= len(c.names) < 12
    for name in c.names:
        assert c.spectrum(name).k == 20
    done = set(c.names)
    summary = coll.run_batch([folder], out, "shells", 20, workers=0)
    assert set(summary.skipped) == done and len(summary.computed) == 12 - len(done)
    assert len(mv.open_collection(out).names) == 12


def test_tasks_ask_for_their_memory_estimate(sources, tmp_path, monkeypatch):
    """A worker offering less memory than two meshes' estimates runs them one at a time,
    though it has two threads."""
    import threading

    running, most = [0], [0]
    lock = threading.Lock()
    compute = pipeline.compute_spectrum

    def counted(*args):
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        try:
            time.sleep(0.05)
            return compute(*args)
        finally:
            with lock:
                running[0] -= 1

    monkeypatch.setattr(pipeline, "compute_spectrum", counted)
    mesh = mv.load_mesh(sources / "torus.obj")
    assert runner.vertex_count_hint(sources / "torus.obj") == mesh.n_vertices
    need = runner.memory_estimate(mesh.n_vertices, runner._parameters("laplacian", K, [], 1, 1))
    with distributed.Client(
        processes=False,
        n_workers=1,
        threads_per_worker=2,
        resources={"memory": int(1.5 * need)},
        dashboard_address=":0",
    ) as client:
        assert runner._memory_resource(client) == int(1.5 * need)
        summary = coll.run_batch(
            [sources / f"{n}.obj" for n in ("torus", "torus_moved", "fat_torus")],
            tmp_path / "store",
            "laplacian",
            K,
            client=client,
        )
    assert len(summary.computed) == 3 and most[0] == 1


def test_sources_folders_globs_and_list_files(sources, tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    for folder in ("a", "b"):
        (tmp_path / folder / "torus.obj").write_bytes((sources / "torus.obj").read_bytes())
    listing = tmp_path / "list.txt"
    listing.write_text("# two files\na/torus.obj\n\nb/torus.obj\n")
    paths = coll.find_meshes([listing, str(tmp_path / "*" / "torus.obj"), sources / "plate.obj"])
    assert [p.name for p in paths] == ["torus.obj", "torus.obj", "plate.obj"]
    assert coll.mesh_names(paths) == ["a--torus", "b--torus", "plate"]
    with pytest.raises(ValueError, match="no such file"):
        coll.find_meshes([tmp_path / "missing"])


def test_import_modalviewer_loads_no_dask_and_no_qt():
    code = (
        "import sys, modalviewer as mv; mv.open_collection; "
        "print(sorted(m for m in sys.modules if m.split('.')[0] in "
        "('dask', 'distributed', 'PySide6', 'qtpy')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0 and out.stdout.strip() == "[]", out.stderr


def test_vertex_count_hints_read_the_headers_of_ply_and_off(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    sphere = primitives.icosphere(2)
    tri = trimesh.Trimesh(sphere.vertices, sphere.faces, process=False)
    n = sphere.n_vertices
    for name, encoding in (("a.ply", "ascii"), ("b.ply", "binary")):
        tri.export(tmp_path / name, encoding=encoding)
        assert runner.vertex_count_hint(tmp_path / name) == n
    off = tmp_path / "c.off"
    tri.export(off)
    off.write_text("# a comment 7 8 9\n" + off.read_text())
    assert runner.vertex_count_hint(off) == n
    tri.export(tmp_path / "d.stl")  # binary: two triangles per vertex on a closed surface
    assert runner.vertex_count_hint(tmp_path / "d.stl") == len(sphere.faces) // 2
    (tmp_path / "e.off").write_text("OFF\n")  # no counts: the file size over 40 bytes
    assert runner.vertex_count_hint(tmp_path / "e.off") == 3


def test_an_existing_scheduler_without_memory_resources(sources, tmp_path):
    notes = []
    with distributed.LocalCluster(
        processes=False, n_workers=1, threads_per_worker=1, dashboard_address=":0"
    ) as cluster:
        summary = coll.run_batch(
            [sources / "sphere.obj", sources / "plate.obj"],
            tmp_path / "store",
            "laplacian",
            K,
            scheduler=cluster.scheduler_address,
            log=notes.append,
        )
    assert sorted(summary.computed) == ["plate", "sphere"]
    assert len(notes) == 1 and "without memory estimates" in notes[0]


def test_files_of_one_name_and_two_formats_side_by_side_are_two_meshes(sources, tmp_path):
    # sphere.obj and sphere.off in one folder: two entries, and a second run computes
    # nothing (one name for both had kept one of them and swapped it at every run)
    folder = tmp_path / "scans"
    folder.mkdir()
    (folder / "sphere.obj").write_bytes((sources / "sphere.obj").read_bytes())
    plate = primitives.grid_plate(6, 5)
    rows = [f"OFF\n{plate.n_vertices} {plate.n_faces} 0"]
    rows += [f"{x!r} {y!r} {z!r}" for x, y, z in plate.vertices.tolist()]
    rows += [f"3 {a} {b} {c}" for a, b, c in plate.faces.tolist()]
    (folder / "sphere.off").write_text("\n".join(rows) + "\n")
    paths = coll.find_meshes([folder])
    assert coll.mesh_names(paths) == ["sphere.obj", "sphere.off"]
    summary = coll.run_batch([folder], tmp_path / "store", "laplacian", K, workers=0)
    assert sorted(summary.computed) == ["sphere.obj", "sphere.off"]
    store = mv.open_collection(tmp_path / "store")
    assert sorted(store.names) == ["sphere.obj", "sphere.off"]
    assert store.spectrum("sphere.off").modes.shape[0] == plate.n_vertices
    again = coll.run_batch([folder], tmp_path / "store", "laplacian", K, workers=0)
    assert again.computed == [] and sorted(again.skipped) == ["sphere.obj", "sphere.off"]


def test_a_file_that_fails_after_it_was_computed_leaves_no_old_result(sources, tmp_path):
    # its old result had stayed beside the new failure: listed in names and in errors,
    # and ranked by `similar`
    folder = tmp_path / "scans"
    folder.mkdir()
    scan = folder / "scan.obj"
    scan.write_bytes((sources / "sphere.obj").read_bytes())
    store = tmp_path / "store"
    assert coll.run_batch([folder], store, "laplacian", K, workers=0).computed == ["scan"]
    scan.write_text("v 0 0 0\nv 1 0\nf 1 2 3\n")  # damaged since
    coll.run_batch([folder], store, "laplacian", K, workers=0)
    c = mv.open_collection(store)
    assert c.names == [] and list(c.errors) == ["scan"]
    assert not (store / "meshes" / "scan.npz").exists()


def test_formats_meshio_reads_are_meshes_in_folders_and_as_sources(sources, tmp_path):
    # a .vtu named as a source was read as a list file (21 failures named after its XML
    # lines) and a folder's search skipped it; an .xml beside it is not taken for a mesh
    meshio = pytest.importorskip("meshio")
    folder = tmp_path / "scans"
    folder.mkdir()
    sphere = mv.load_mesh(sources / "sphere.obj")
    meshio.write_points_cells(folder / "ball.vtu", sphere.vertices, [("triangle", sphere.faces)])
    (folder / "notes.xml").write_text("<notes>not a mesh</notes>\n")
    (folder / "plate.obj").write_bytes((sources / "plate.obj").read_bytes())
    assert [p.name for p in coll.find_meshes([folder])] == ["ball.vtu", "plate.obj"]
    assert coll.find_meshes([folder / "ball.vtu"]) == [folder / "ball.vtu"]
    summary = coll.run_batch([folder / "ball.vtu"], tmp_path / "store", "laplacian", K, workers=0)
    assert summary.computed == ["ball"]
    assert (
        mv.open_collection(tmp_path / "store").spectrum("ball").modes.shape[0] == sphere.n_vertices
    )


def test_batch_prints_its_summary_first_and_names_recorded_failures(sources, tmp_path, capsys):
    from modalviewer.cli import main

    files = [str(sources / "sphere.obj"), str(sources / "broken.obj")]
    argv = ["batch", *files, "-o", str(tmp_path / "s"), "-k", "6", "--workers", "0"]
    assert main(argv) == 1
    lines = capsys.readouterr().out.splitlines()
    assert "1 computed, 0 already done, 1 failed" in lines[0]
    assert lines[1].startswith("failed: broken: ")
    assert main(argv) == 0  # the failure is recorded, not tried again
    lines = capsys.readouterr().out.splitlines()
    assert "0 computed, 2 already done (1 of them recorded failures, not tried again" in lines[0]
    assert lines[1] == "recorded failures not tried again: broken"
