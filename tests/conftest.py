"""Settings for every test: Qt off screen, and a spectrum cache and window settings that
belong to the test run (one folder per pytest-xdist worker), so that no test reads or
fills the user's ``~/.cache/modalviewer`` and a run starts from a fresh machine's state.

``make test`` runs the tests on two pytest-xdist workers.  Each worker and the processes
it starts then use one BLAS/OpenMP thread (set here before numpy loads, unless already
set), so that two workers do not ask for four threads on two cores."""

import os

import pytest

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
