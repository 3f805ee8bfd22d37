"""Mesh repairs offered by the viewer, through the model (no Qt)."""

import numpy as np

from benchmarks.slivers import add_slivers
from modalviewer.core.cache import SpectrumCache
from modalviewer.core.mesh import Mesh
from modalviewer.core.primitives import icosphere
from modalviewer.viewer import ViewerModel
from modalviewer.viewer.jobs import DONE
from modalviewer.viewer.session import restore_session, save_session


def _two_spheres(tmp_path):
    import trimesh

    big, small = icosphere(2), icosphere(1)
    v = np.vstack([big.vertices, 0.3 * small.vertices + [3.0, 0.0, 0.0]])
    f = np.vstack([big.faces, small.faces + big.n_vertices])
    path = tmp_path / "two.ply"
    trimesh.Trimesh(v, f, process=False).export(path)
    return path


def test_keep_the_largest_component_replaces_the_mesh_and_survives_a_session(tmp_path):
    model = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    model.open_mesh(_two_spheres(tmp_path))
    assert model.state.mesh.n_components == 2
    job = model.repair("largest_component")
    model.jobs.wait(job)
    assert job.status == DONE
    mesh = model.state.mesh
    assert mesh.n_components == 1 and mesh.n_vertices == icosphere(2).n_vertices
    assert model.state.mesh_repairs == ["largest_component"]
    assert "removed" in str(mesh.report)
    model.jobs.wait(model.request_spectrum("laplacian", k=8, show=True))
    session = save_session(model.state, tmp_path / "s.json")
    other = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    restored = restore_session(other, session)
    for j in restored.jobs:
        other.jobs.wait(j)
    assert restored.notes == []
    assert other.state.mesh.hash == mesh.hash and other.state.display.kind == "mode"


def test_fix_slivers_from_the_viewer_improves_the_worst_triangle(tmp_path):
    import trimesh

    v, f = add_slivers(icosphere(3), needles=10, caps=10, eps=1e-4, seed=1)
    path = tmp_path / "slivers.ply"
    trimesh.Trimesh(v, f, process=False).export(path)
    model = ViewerModel(cache=SpectrumCache(tmp_path / "cache"))
    model.open_mesh(path)
    before = model.state.mesh

    def worst_quality(mesh: Mesh) -> float:
        e = mesh.vertices[mesh.faces[:, [1, 2, 0]]] - mesh.vertices[mesh.faces]
        return float(np.min(4 * np.sqrt(3) * mesh.face_areas / (e**2).sum(axis=(1, 2))))

    job = model.repair("fix_slivers")
    model.jobs.wait(job, timeout=120)
    assert job.status == DONE, job.error
    after = model.state.mesh
    assert after is not before and model.state.mesh_repairs == ["fix_slivers"]
    assert worst_quality(before) < 0.01 < worst_quality(after)
    assert after.n_boundary_edges == 0 and after.n_components == 1


def test_a_process_that_repaired_and_then_computed_exits_cleanly(tmp_path):
    """MeshLab run in a worker thread, then MKL's solver, corrupted the heap: the process
    aborted at exit (status 134, "malloc_consolidate(): unaligned fastbin chunk").  The
    viewer runs repairs in a child process."""
    import subprocess
    import sys

    script = f"""
import trimesh
from pathlib import Path
from modalviewer.core.cache import SpectrumCache
from benchmarks.slivers import add_slivers
from modalviewer.core.primitives import icosphere
from modalviewer.viewer import ViewerModel
tmp = Path({str(tmp_path)!r})
v, f = add_slivers(icosphere(3), needles=10, caps=10, eps=1e-4, seed=1)
trimesh.Trimesh(v, f, process=False).export(tmp / "s.ply")
model = ViewerModel(cache=SpectrumCache(tmp / "cache"))
model.open_mesh(tmp / "s.ply")
job = model.repair("fix_slivers")
model.jobs.wait(job, timeout=120)
spec = model.jobs.wait(model.request_spectrum("laplacian", k=20)).result[0]
print(job.status, spec.k)
"""
    run = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-1000:]
    assert run.stdout.split() == ["done", "20"]


def test_a_failed_sliver_repair_before_a_retry_is_reported(tmp_path, monkeypatch):
    """The repair fix_slivers_and_retry starts tells the user when it fails, as
    repair_mesh's does (its failure had reached no message: the job-finished handler
    leaves repairs to their own callback, which only repair_mesh attached)."""
    from modalviewer.viewer import Viewer, model
    from modalviewer.viewer.jobs import FAILED
    from modalviewer.viewer.state import SpectrumKey

    def broken(name, mesh, progress, cancel):
        raise RuntimeError("the repair broke")

    monkeypatch.setattr(model, "repair_in_process", broken)
    viewer = Viewer(cache=SpectrumCache(tmp_path / "cache"))
    errors = []
    viewer.events.error.connect(lambda title, text: errors.append((title, text)))
    viewer.set_mesh(icosphere(2))
    job = viewer.fix_slivers_and_retry(SpectrumKey("laplacian", 8))
    viewer.wait_for(job)
    assert job.status == FAILED
    assert errors == [("Repair failed", f"{job.description} failed: the repair broke")]
    assert viewer.state.mesh.hash == icosphere(2).hash and not viewer.jobs.jobs
