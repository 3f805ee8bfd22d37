"""Memory settings of computation processes (modalviewer.processes.memory)."""

import subprocess
import sys

import pytest


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_the_memory_settings_take_effect_in_a_fresh_process():
    code = (
        "from modalviewer.processes.memory import prepare_compute_process\n"
        "import numpy as np\n"
        "ok = prepare_compute_process()\n"
        "a = np.ones((4000, 4000)); del a\n"  # 128 MB from the heap, kept
        # the setter returns the previous setting: huge-page advice is off
        "assert np._core.multiarray._set_madvise_hugepage(True) is False\n"
        "print(ok)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "True"


def test_the_viewer_child_process_computes_with_the_memory_settings(tmp_path):
    """The viewer's child process (processes.job_main) computes with the settings on and
    still writes its spectrum."""
    import numpy as np

    from modalviewer.core.primitives import icosphere

    mesh = icosphere(2)
    job = tmp_path / "job.npz"
    np.savez(
        job,
        vertices=mesh.vertices,
        faces=mesh.faces,
        params='{"operator": "laplacian", "k": 10, "bending": 1, "membrane": 1}',
    )
    out = tmp_path / "out.npz"
    run = subprocess.run(
        [sys.executable, "-m", "modalviewer.processes.job_main", str(job), str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert out.is_file()
