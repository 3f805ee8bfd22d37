"""Settings for every test: Qt off screen, and a spectrum cache and window settings that
belong to the test run (one folder per pytest-xdist worker), so that no test reads or
fills the user's ``~/.cache/modalviewer`` and a run starts from a fresh machine's state.

``make test`` runs the tests on two pytest-xdist workers.  Each worker and the processes
it starts then use one BLAS/OpenMP thread (set here before numpy loads, unless already
set), so that two workers do not ask for four threads on two cores."""

import os
import shutil
import site
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

if os.environ.get("PYTEST_XDIST_WORKER"):
    for _name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ.setdefault(_name, "1")


@pytest.fixture(scope="session", autouse=True)
def _own_cache_and_settings(tmp_path_factory):
    home = tmp_path_factory.mktemp("user")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MODALVIEWER_CACHE", str(home / "cache"))
        mp.setenv("MODALVIEWER_SETTINGS", str(home / "settings.ini"))
        yield


def _run(*args, **kwargs):
    out = subprocess.run(args, capture_output=True, text=True, timeout=600, **kwargs)
    assert out.returncode == 0, f"{args}\n{out.stdout}\n{out.stderr}"
    return out


@pytest.fixture(scope="session")
def installed_wheel(tmp_path_factory):
    """(wheel, python, folder): a wheel built from a copy of the repository and installed
    without dependencies into a fresh environment in ``folder/env``.  No network: the
    fresh environment sees this environment's packages (a .pth file naming its
    site-packages)."""
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


@pytest.fixture(scope="session")
def codebase_metrics():
    """``scripts/codebase_metrics.py`` as a module: how the package's sources, imports,
    functions and docstrings are read, for the architecture and shape tests."""
    import importlib.util

    script = Path(__file__).resolve().parents[1] / "scripts" / "codebase_metrics.py"
    spec = importlib.util.spec_from_file_location("codebase_metrics", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
