"""A wheel built from the repository installs into a fresh environment and works there:
the bundled meshes come along, a computation runs, ``python -m modalviewer --help``
answers (the ``installed_wheel`` fixture of conftest.py: no network, the wheel installed
without dependencies).  tests/test_gallery.py runs every gallery script from it."""

import subprocess
import zipfile
from pathlib import Path


def _run(*args, **kwargs):
    out = subprocess.run(args, capture_output=True, text=True, timeout=600, **kwargs)
    assert out.returncode == 0, f"{args}\n{out.stdout}\n{out.stderr}"
    return out


def test_the_wheel_carries_the_bundled_meshes(installed_wheel):
    wheel, _, _ = installed_wheel
    names = zipfile.ZipFile(wheel).namelist()
    assets = sorted(Path(n).name for n in names if "/share/modalviewer/assets/" in n)
    assert {"spot.obj", "demo_plate.obj", "demo_landmarks.json"} <= set(assets)
    assert not any(n.startswith("assets/") for n in names)


def test_the_installed_package_computes_and_answers_help(installed_wheel):
    _, python, work = installed_wheel
    code = (
        "import modalviewer as mv, pathlib\n"
        "assert 'site-packages' in mv.__file__, mv.__file__\n"
        "print(mv.asset_path('spot.obj'))\n"
        "mesh = mv.load_mesh(mv.asset_path('demo_plate.obj'))\n"
        "spec = mv.compute_spectrum(mesh, 'laplacian', k=6)\n"
        "print(spec.k, spec.eigenvalues[1] > 0)\n"
    )
    out = _run(python, "-c", code, cwd=work)
    lines = out.stdout.split("\n")
    assert str(work / "env") in lines[0] and lines[1] == "6 True"
    out = _run(python, "-m", "modalviewer", "--help", cwd=work)
    assert "usage: modalviewer" in out.stdout and "default: the bundled mesh" in out.stdout
