"""A wheel built from the repository installs into a fresh environment and works there:
the bundled meshes come along, a computation runs, ``python -m modalviewer --help``
answers.  No network: the fresh environment sees this environment's packages (a .pth
file naming its site-packages) and the wheel is installed without dependencies."""

import shutil
import site
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _run(*args, **kwargs):
    out = subprocess.run(args, capture_output=True, text=True, timeout=600, **kwargs)
    assert out.returncode == 0, f"{args}\n{out.stdout}\n{out.stderr}"
    return out


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    pytest.importorskip("setuptools")
    work = tmp_path_factory.mktemp("wheel")
    src = work / "src"  # a copy: the build leaves nothing in the work tree
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info", "build")
    for name in ("modalviewer", "assets"):
        shutil.copytree(ROOT / name, src / name, ignore=ignore)
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        if (ROOT / name).exists():
            shutil.copy(ROOT / name, src / name)
    pip = (sys.executable, "-m", "pip")
    _run(*pip, "wheel", "--quiet", "--no-deps", "--no-build-isolation", "-w", work / "dist", src)
    (wheel,) = (work / "dist").glob("modalviewer-*.whl")
    env_dir = work / "env"
    _run(sys.executable, "-m", "venv", "--without-pip", env_dir)
    python = env_dir / "bin" / "python"
    purelib = Path(
        _run(python, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))").stdout.strip()
    )
    here = {sysconfig.get_path("purelib"), sysconfig.get_path("platlib"), *site.getsitepackages()}
    (purelib / "outer_packages.pth").write_text("\n".join(sorted(here)) + "\n")
    _run(*pip, "--python", python, "install", "--quiet", "--no-deps", "--no-build-isolation", wheel)
    return wheel, python, work


def test_the_wheel_carries_the_bundled_meshes(installed):
    wheel, _, _ = installed
    import zipfile

    names = zipfile.ZipFile(wheel).namelist()
    assets = sorted(Path(n).name for n in names if "/share/modalviewer/assets/" in n)
    assert {"spot.obj", "demo_plate.obj", "demo_landmarks.json"} <= set(assets)
    assert not any(n.startswith("assets/") for n in names)


def test_the_installed_package_computes_and_answers_help(installed):
    _, python, work = installed
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


GALLERY = sorted((ROOT / "examples" / "gallery").glob("[0-9]*.py"))


@pytest.mark.parametrize("script", GALLERY, ids=[p.stem for p in GALLERY])
def test_each_gallery_script_runs_from_the_installed_wheel(installed, script, tmp_path):
    """A copy of the script, run in a folder outside the checkout by the fresh
    environment's Python: its meshes must come from the wheel (``mv.asset_path``), not
    from a path next to the package's source."""
    _, python, work = installed
    import os

    run_in = tmp_path / "run"
    run_in.mkdir()
    shutil.copy(script, run_in / script.name)
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", MODALVIEWER_CACHE=str(work / "cache"))
    env.pop("PYTHONPATH", None)
    out = subprocess.run(
        [python, script.name], cwd=run_in, env=env, capture_output=True, text=True, timeout=600
    )
    assert out.returncode == 0, out.stderr[-3000:]
    pngs = list(run_in.glob("*.png"))
    assert pngs and all(p.stat().st_size > 1000 for p in pngs), script.name
