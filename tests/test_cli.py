"""The headless command line: results, one-line errors, exit codes."""

import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

import modalviewer as mv

ASSETS = Path(__file__).resolve().parents[1] / "assets"


def _run(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "modalviewer", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )


def test_compute_writes_a_spectrum(tmp_path):
    out = tmp_path / "s.npz"
    r = _run(
        "compute",
        ASSETS / "demo_double_torus.obj",
        "--operator",
        "modified_dirichlet",
        "-k",
        12,
        "-o",
        out,
    )
    assert r.returncode == 0, r.stderr
    spec = mv.load_spectrum(out)
    assert spec.operator == "modified_dirichlet" and spec.k == 12
    assert "Traceback" not in r.stderr
    assert "solver:" in r.stdout and f"({spec.parameters['operator_columns']} operator" in r.stdout


def test_render_and_distance_images(tmp_path):
    png = tmp_path / "mode.png"
    r = _run(
        "render",
        ASSETS / "demo_folded_plate.obj",
        "--operator",
        "laplacian",
        "--mode",
        3,
        "-k",
        8,
        "--size",
        "320x240",
        "-o",
        png,
    )
    assert r.returncode == 0, r.stderr
    assert Image.open(png).size == (320, 240)
    csv = tmp_path / "d.csv"
    r = _run(
        "distance",
        ASSETS / "demo_plate.obj",
        "--vertex",
        0,
        "--kind",
        "hks",
        "-k",
        20,
        "--csv",
        csv,
        "--threshold",
        0.2,
        "-o",
        tmp_path / "d.png",
    )
    assert r.returncode == 0, r.stderr
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert rows.shape == (1225, 2) and rows[0, 1] == 0.0
    assert Image.open(tmp_path / "d.png").size == (1024, 768)


def test_errors_are_one_line(tmp_path):
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    cases = [
        (("compute", empty, "-o", tmp_path / "x.npz"), 1, "empty"),
        (("compute", tmp_path / "missing.obj", "-o", tmp_path / "x.npz"), 1, "no such file"),
        (("compute", ASSETS / "demo_plate.obj", "--operator", "nope", "-o", "x.npz"), 2, "invalid"),
        (("distance", ASSETS / "demo_plate.obj", "--vertex", 10**6), 1, "--vertex"),
        (
            ("render", ASSETS / "demo_plate.obj", "--mode", 1, "--size", "big", "-o", "x.png"),
            2,
            "size",
        ),
    ]
    for args, code, fragment in cases:
        r = _run(*args)
        assert r.returncode == code, (args, r.stderr)
        lines = [line for line in r.stderr.splitlines() if line.startswith("modalviewer: error")]
        assert len(lines) == 1 and fragment in lines[0], r.stderr
        assert "Traceback" not in r.stderr


def test_help_lists_the_subcommands():
    from modalviewer.cli import COMMANDS

    out = _run("--help")
    assert out.returncode == 0, out.stderr
    for command in COMMANDS:
        assert f"\n  {command} " in out.stdout, out.stdout
