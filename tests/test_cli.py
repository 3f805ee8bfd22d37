"""The headless command line: results, one-line errors, exit codes."""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import modalviewer as mv

ASSETS = Path(__file__).resolve().parents[1] / "assets"


def _run(*args, cwd=None, env=None):
    return subprocess.run(
        [sys.executable, "-m", "modalviewer", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=600,
    )


def _assert_one_argument_error(main, argv, fragment, capsys):
    """``main(argv)`` exits with code 2 and one "modalviewer: error" line holding
    ``fragment``."""
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    err = capsys.readouterr().err
    assert exit_.value.code == 2
    lines = [line for line in err.splitlines() if line.startswith("modalviewer: error")]
    assert len(lines) == 1 and fragment in lines[0], err


def _error_lines(stderr):
    return [line for line in stderr.splitlines() if line.startswith("modalviewer: error")]


@pytest.fixture(scope="module")
def sliver_obj(tmp_path_factory):
    """A sphere with 20 needles and 20 caps of quality 1e-8, whose shells Hessian cannot
    be factorised (as in tests/gui/test_sliver_retry.py)."""
    from benchmarks.slivers import add_slivers
    from modalviewer.core.primitives import icosphere

    v, f = add_slivers(icosphere(3), needles=20, caps=20, eps=1e-8, seed=2)
    path = tmp_path_factory.mktemp("slivers") / "slivered.obj"
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in v] + [
        f"f {a} {b} {c}" for a, b, c in f + 1
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_fix_slivers_option_repairs_and_is_advised_where_factorisation_fails(sliver_obj, tmp_path):
    out = tmp_path / "s.npz"
    r = _run("compute", sliver_obj, "--operator", "shells", "-k", 12, "-o", out)
    assert r.returncode == 1 and not out.exists()
    (line,) = _error_lines(r.stderr)
    assert "could not be factorised" in line and line.endswith("; retry with --fix-slivers")
    assert "Traceback" not in r.stderr
    r = _run("compute", sliver_obj, "--operator", "shells", "-k", 12, "--fix-slivers", "-o", out)
    assert r.returncode == 0, r.stderr
    # measured: 195 of 1360 triangles changed, 60 below quality 0.05 -> 0, 0.02 s
    assert "slivered.obj: fix slivers: Changed " in r.stdout
    assert "triangles below quality 0.05 60 -> 0" in r.stdout
    spec = mv.load_spectrum(out)
    assert spec.k == 12 and spec.null_space_dimension == 6 and spec.eigenvalues[6] > 1.0
    png = tmp_path / "m.png"
    r = _run(
        "render", sliver_obj, "--operator", "shells", "-k", 12, "--mode", 7, "--fix-slivers",
        "--size", "320x240", "-o", png,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "fix slivers: Changed " in r.stdout and Image.open(png).size == (320, 240)
    csv = tmp_path / "d.csv"
    base = ("distance", sliver_obj, "--vertex", 0, "--kind", "vibration", "-k", 12, "--csv", csv)
    r = _run(*base, env={**os.environ, "MODALVIEWER_CACHE": str(tmp_path / "cache")})
    assert r.returncode == 1 and _error_lines(r.stderr)[0].endswith("retry with --fix-slivers")
    r = _run(*base, "--fix-slivers", env={**os.environ, "MODALVIEWER_CACHE": str(tmp_path / "c")})
    assert r.returncode == 0, r.stderr
    assert "fix slivers: Changed " in r.stdout
    assert np.loadtxt(csv, delimiter=",", skiprows=1).shape == (662, 2)  # 20 vertices fewer


def test_fix_slivers_without_pymeshlab_says_how_to_install_it(sliver_obj, tmp_path):
    (tmp_path / "pymeshlab.py").write_text("raise ImportError('no pymeshlab here')\n")
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    r = _run("compute", sliver_obj, "--fix-slivers", "-o", tmp_path / "s.npz", env=env)
    assert r.returncode == 2
    (line,) = _error_lines(r.stderr)
    assert "--fix-slivers needs the optional package pymeshlab" in line
    assert "pip install 'modalviewer[repair]'" in line
    assert "Traceback" not in r.stderr


def test_compute_prints_a_spectrum_of_zero_modes_as_a_warning(tmp_path):
    r = _run("compute", ASSETS / "demo_plate.obj", "-k", 1, "-o", tmp_path / "s.npz")
    assert r.returncode == 0, r.stderr
    warned = [x for x in r.stderr.splitlines() if "modalviewer: warning: " in x]
    assert len(warned) == 1 and "the only mode is an exact zero mode" in warned[0]
    assert "k is not larger than the null space's dimension" in warned[0]
    assert "warnings.warn" not in r.stderr and "ZeroModesWarning" not in r.stderr


def test_compute_says_when_fewer_modes_came_than_asked_for(tmp_path):
    """A small mesh has as many modes as unknowns: asked for more, the summary says so
    (it only said "wrote ... (spectrum, 126 shells modes)")."""
    from modalviewer.core.primitives import icosphere

    mesh = icosphere(1)
    path = tmp_path / "ico42.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in mesh.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh.faces]
    path.write_text("\n".join(lines) + "\n")
    r = _run("compute", path, "--operator", "shells", "-k", 500, "-o", tmp_path / "s.npz")
    assert r.returncode == 0, r.stderr
    assert "asked for 500 modes, 126 came: all the mesh has (126 unknowns)" in r.stdout


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
    assert f"wrote {out} (spectrum, 12 modified_dirichlet modes)" in r.stdout.splitlines()


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
    assert f"wrote {png} (PNG 320x240, mode 3)" in r.stdout.splitlines()
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
        "--share",
        0.2,
        "-o",
        tmp_path / "d.png",
    )
    assert r.returncode == 0, r.stderr
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert rows.shape == (1225, 2) and rows[0, 1] == 0.0
    assert Image.open(tmp_path / "d.png").size == (1024, 768)
    lines = r.stdout.splitlines()
    assert f"wrote {csv} (CSV, 1225 rows vertex,distance: hks distance from vertex 0)" in lines
    assert f"wrote {tmp_path / 'd.png'} (PNG 1024x768, hks distance map)" in lines


def _threshold_line(stdout):
    """(distance, per cent of the area) of the CLI's threshold line."""
    line = next(x for x in stdout.splitlines() if x.startswith("threshold "))
    words = line.split()
    return float(words[1]), float(words[words.index("%") - 1])


def test_distance_share_and_threshold_are_area_share_and_distance(tmp_path):
    from modalviewer.core.laplacian import lumped_masses
    from modalviewer.viewer.state import DEFAULT_THRESHOLD_SHARE

    plate = ASSETS / "demo_plate.obj"
    areas = lumped_masses(mv.load_mesh(plate))
    csv = tmp_path / "d.csv"
    base = ("distance", plate, "--vertex", 0, "--kind", "hks", "-k", 20, "--csv", csv)
    measured = {}
    for extra in (["--share"], ["--share", 0.05], ["--threshold", 0.3]):
        r = _run(*base, *extra)
        assert r.returncode == 0, r.stderr
        d = np.loadtxt(csv, delimiter=",", skiprows=1)[:, 1]
        value, percent = _threshold_line(r.stdout)
        # the value is printed to 6 digits, the CSV to 10, and the plate's symmetry ties
        # distances: the share is bracketed by the sub-level sets just below and above
        tol = 1e-5 * d.max()
        below = areas[d < value - tol].sum() / areas.sum()
        covered = areas[d <= value + tol].sum() / areas.sum()
        assert below <= percent / 100 <= covered + 5e-5, (extra, below, covered, percent)
        measured[tuple(extra)] = value, percent / 100
        if extra[0] == "--share":
            share = DEFAULT_THRESHOLD_SHARE if len(extra) == 1 else extra[1]
            # the smallest distance of the map whose sub-level set covers the share
            assert below < share <= covered, (extra, below, covered)
    # measured: 0.28028 marks 10.01 %, 0.157067 marks 5.21 % (four vertices at that
    # distance to 1e-14 by the plate's symmetry, all marked: 5.09 % marked three of them);
    # --threshold 0.3 (a distance, 0.159 of the largest, not a fraction of it) marks
    # 10.65 % of the area
    assert DEFAULT_THRESHOLD_SHARE == 0.1
    assert abs(measured[("--share",)][1] - 0.1001) < 1e-3
    assert abs(measured[("--share", 0.05)][1] - 0.0521) < 1e-3
    assert measured[("--threshold", 0.3)][0] == 0.3
    assert abs(measured[("--threshold", 0.3)][1] - 0.1065) < 1e-3
    r = _run(*base, "--share", 0.1, "--threshold", 0.3)
    assert r.returncode == 2 and "not allowed with argument --share" in r.stderr
    r = _run(*base, "--share", 1.5)
    assert r.returncode == 2 and "argument --share: must be in (0, 1], got 1.5" in r.stderr


def test_errors_are_one_line(tmp_path):
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    cases = [
        (("compute", empty, "-o", tmp_path / "x.npz"), 1, "empty"),
        (("compute", tmp_path / "missing.obj", "-o", tmp_path / "x.npz"), 1, "no such file"),
        (("compute", ASSETS / "demo_plate.obj", "--operator", "nope", "-o", "x.npz"), 2, "invalid"),
        (("distance", ASSETS / "demo_plate.obj", "--vertex", 10**6), 2, "--vertex"),
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


@pytest.mark.parametrize(
    "args, fragment",
    [
        (("compute", "-k", "0"), "argument -k: must be at least 1, got 0"),
        (("compute", "-k", "2.5"), "argument -k: a whole number is needed, got '2.5'"),
        (("compute", "--bending", "-1"), "argument --bending: must be a finite number >= 0"),
        (("compute", "--membrane", "nan"), "argument --membrane: must be a finite number"),
        (("render", "--mode", "-1"), "argument --mode: must be at least 0, got -1"),
        (("render", "--mode", "1", "--isolines", "-3"), "argument --isolines: must be at least 0"),
        (("distance", "--vertex", "-1"), "argument --vertex: must be at least 0, got -1"),
        (("distance", "--vertex", "1", "--share", "0"), "argument --share: must be in (0, 1]"),
        (("distance", "--vertex", "1", "--threshold", "-1"), "argument --threshold: must be a"),
        (("batch", "-k", "0"), "argument -k: must be at least 1, got 0"),
    ],
)
def test_values_out_of_range_are_argument_errors(args, fragment, capsys):
    # exit code 2 and one line naming the argument, before any file is read (they were
    # exit code 1 after the mesh was loaded, and --isolines -3 was taken)
    from modalviewer import cli

    command, *rest = args
    out = ["-o", "x.png"] if command == "render" else (["-o", "s"] if command == "batch" else [])
    out += ["-o", "x.npz"] if command == "compute" else []
    _assert_one_argument_error(cli.main, [command, "missing.obj", *rest, *out], fragment, capsys)


def test_a_mode_beyond_those_computed_is_an_argument_error(tmp_path):
    r = _run("render", ASSETS / "demo_plate.obj", "--mode", 9, "-k", 6, "-o", tmp_path / "x.png")
    assert r.returncode == 2 and "modalviewer: error: --mode must be between 0 and 5" in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_help_lists_the_subcommands():
    from modalviewer.cli import COMMANDS

    out = _run("--help")
    assert out.returncode == 0, out.stderr
    for command in COMMANDS:
        assert f"\n  {command} " in out.stdout, out.stdout


def test_compute_refuses_what_does_not_fit_and_says_what_would(tmp_path, monkeypatch, capsys):
    """As in the viewer: an exact computation expected to need more than its share of the
    machine's memory is refused before it starts, with the most modes that fit."""
    from modalviewer import cli
    from modalviewer.core import memory

    monkeypatch.setattr(memory, "physical_memory_mb", lambda: 64.0)  # 64 MiB
    code = cli.main(
        [
            "compute",
            str(ASSETS / "spot.obj"),
            "--operator",
            "shells",
            "-k",
            "300",
            "-o",
            str(tmp_path / "s.npz"),
        ]
    )
    err = capsys.readouterr().err
    assert code == 1 and "GiB of memory" in err and "modes fit" in err
    assert not (tmp_path / "s.npz").exists()


def test_compute_says_when_the_factor_and_basis_were_kept_small(tmp_path):
    # 29k vertices, 88k unknowns: the shells factor (about 180 MB in core, above the
    # 140 MB working buffer out of core) does not fit a 1 MB limit, so it goes out of
    # core; the spectrum is the one computed in core
    from modalviewer.core.demo_shapes import bumpy_plate
    from modalviewer.core.factor import available_backends
    from modalviewer.viewer.wording import FLOAT32_BASIS_WORDS, OUT_OF_CORE_WORDS

    if "pardiso" not in available_backends():
        pytest.skip("out of core is PARDISO's (the mkl wheel)")
    plate = bumpy_plate(170)
    path = tmp_path / "plate.obj"
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in plate.vertices]
    path.write_text("\n".join(lines + [f"f {a} {b} {c}" for a, b, c in plate.faces + 1]) + "\n")
    runs = {}
    for name, limit in (("tight", "1"), ("free", "1000000")):
        env = {
            **os.environ,
            "MODALVIEWER_CACHE": str(tmp_path / f"cache-{name}"),
            "MODALVIEWER_MEMORY_LIMIT_MB": limit,
            "MODALVIEWER_FACTOR_DIR": str(tmp_path),
        }
        out = tmp_path / f"{name}.npz"
        r = _run("compute", path, "--operator", "shells", "-k", 20, "-o", out, env=env)
        assert r.returncode == 0, r.stderr
        runs[name] = (r.stdout, mv.load_spectrum(out))
    # within 1 MB even the Krylov basis is kept in single precision
    said = f"{OUT_OF_CORE_WORDS} and {FLOAT32_BASIS_WORDS} (memory limit)"
    assert said in runs["tight"][0], runs["tight"][0]
    assert OUT_OF_CORE_WORDS not in runs["free"][0]
    assert FLOAT32_BASIS_WORDS not in runs["free"][0]
    assert runs["tight"][1].parameters["factor_out_of_core"]
    assert runs["tight"][1].parameters["basis_float32"]
    # the final double-precision step: eigenvalues as in core to 1e-9
    np.testing.assert_allclose(
        runs["tight"][1].eigenvalues, runs["free"][1].eigenvalues, rtol=1e-9, atol=1e-9
    )
    assert not list(tmp_path.glob("modalviewer-factor-*"))  # the factor files are gone


def test_the_progress_bar_leaves_no_end_of_a_longer_stage_behind(capsys, monkeypatch):
    from modalviewer.cli import common

    clock = iter([1.0, 2.0])
    monkeypatch.setattr(common.time, "perf_counter", lambda: next(clock))
    monkeypatch.setattr(common, "BAR", {"open": False})  # the open bar stays in this test
    bar = common.progress_bar()
    bar("computing the null space", 0.1)
    bar("factorising", 0.3)
    last = capsys.readouterr().err.split("\r")[-1]
    assert last.rstrip().endswith("factorising")
    assert len(last) == len("[") + 30 + len("]  30.0% ") + len("computing the null space")


def test_the_progress_bar_draws_a_new_stage_at_once(capsys, monkeypatch):
    """A stage that came 0.1 s after "assembling" was not drawn, though the wait it
    names then lasted seconds.  A new stage is drawn at once; the same stage's progress
    at most five times a second."""
    from modalviewer.cli import common

    clock = iter([1.0, 1.1, 1.15, 1.5])
    monkeypatch.setattr(common.time, "perf_counter", lambda: next(clock))
    monkeypatch.setattr(common, "BAR", {"open": False})
    bar = common.progress_bar()
    bar("assembling", 0.0)
    bar("factorising", 0.05)  # 0.1 s later: a new stage
    bar("factorising", 0.06)  # 0.05 s later, same stage: not drawn
    bar("factorising", 0.07)  # 0.4 s after the last drawing
    drawn = capsys.readouterr().err.split("\r")[1:]
    assert [d.split("% ")[1].rstrip() for d in drawn] == [
        "assembling",
        "factorising",
        "factorising",
    ]
    assert "7.0%" in drawn[-1]


def test_a_truncated_file_is_refused_with_the_command_lines_advice(tmp_path, capsys):
    """A truncated OBJ: ``compute`` refuses it naming the place of the damage and the
    advice that works on the command line (--partial, not the viewer's "Open anyway" or
    the library's strict=False); with --partial it computes on the whole records and
    says what was dropped."""
    from modalviewer import cli

    text = (ASSETS / "spot.obj").read_text()
    cut = text.rfind("\nf ") + 4  # within the last face's record
    broken = tmp_path / "cut.obj"
    broken.write_text(text[:cut])
    out = tmp_path / "s.npz"
    args = ["compute", str(broken), "--operator", "laplacian", "-k", "5", "-o", str(out)]
    assert cli.main(args) == 1
    err = capsys.readouterr().err
    assert "cut.obj" in err and "--partial reads its whole records" in err, err
    assert "Open anyway" not in err and "strict=False" not in err
    assert not out.exists()
    assert cli.main([*args, "--partial"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("cut.obj: "), printed
    assert out.exists()


def test_a_picture_named_for_another_format_is_refused_before_any_work(tmp_path, capsys):
    # -o fig.jpg had written fig.png (PNG data, another name than asked for)
    from modalviewer import cli
    from modalviewer.scene.export import png_path

    code = cli.main(
        ["render", str(ASSETS / "spot.obj"), "--mode", "3", "-o", str(tmp_path / "f.jpg")]
    )
    err = capsys.readouterr().err
    assert code == 2 and "-o " in err and "pictures are written as PNG" in err
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(ValueError, match="give a name ending in .png"):
        png_path(tmp_path / "f.TIFF")
    assert png_path(tmp_path / "fig_t0.5") == tmp_path / "fig_t0.5.png"  # a suffix kept
    assert png_path(tmp_path / "f.PNG") == tmp_path / "f.PNG"


def test_the_two_mesh_distance_figure_has_a_colour_bar(tmp_path):
    # the distance panel of `distance A --to B` drew no colour bar: its colours had no
    # values; now a bar (continuous) or a two-swatch legend (threshold) as in the viewer
    from PIL import Image

    spot = ASSETS / "spot.obj"
    base = ("distance", spot, "--vertex", 5, "--to", spot, "--kind", "hks", "-k", 12)
    pictures = {}
    for name, extra in (("continuous", ()), ("threshold", ("--share", 0.1))):
        out = tmp_path / f"{name}.png"
        r = _run(*base, *extra, "--size", "800x600", "-o", out)
        assert r.returncode == 0, r.stderr
        pictures[name] = np.asarray(Image.open(out).convert("RGB")).astype(int)
    img = pictures["continuous"]
    bottom = img[int(0.85 * img.shape[0]) :, img.shape[1] // 2 :]  # under panel B
    r, g, b = bottom[..., 0], bottom[..., 1], bottom[..., 2]
    assert ((r > 150) & (g < 80) & (b < 80)).sum() > 50  # the bar's red end
    img = pictures["threshold"]
    bottom = img[int(0.85 * img.shape[0]) :, img.shape[1] // 2 :]
    r, g, b = bottom[..., 0], bottom[..., 1], bottom[..., 2]
    assert ((b > r + 60) & (b > g + 20)).sum() > 20  # the blue swatch


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["batch", "x", "-o", "s", "--workers", "-1"], "argument --workers: must be at least 0"),
        (["batch", "x", "-o", "s", "--memory-limit", "-3"], "argument --memory-limit: must be a"),
        (["similar", "store", "mesh.obj", "-n", "0"], "argument -n: must be at least 1, got 0"),
    ],
)
def test_collection_commands_refuse_values_out_of_range_as_argument_errors(argv, fragment, capsys):
    from modalviewer import cli

    with pytest.raises(SystemExit) as exit_:
        cli.main(argv)
    assert exit_.value.code == 2 and fragment in capsys.readouterr().err


@pytest.mark.parametrize(
    "args, fragment",
    [
        (("-k", "0"), "argument -k: must be at least 1, got 0"),
        (("-k", "2.5"), "argument -k: a whole number is needed, got '2.5'"),
        (("--mode", "-3"), "argument --mode: must be at least 0, got -3"),
    ],
)
def test_the_viewers_own_values_out_of_range_are_argument_errors(args, fragment, capsys):
    # as the headless commands': exit code 2 before any window or file (the viewer took
    # --mode -3 and showed a mode counted from the end, and -k 0 failed after loading)
    from modalviewer.gui import app

    _assert_one_argument_error(app.main, ["missing.obj", *args], fragment, capsys)


def test_the_viewers_mode_beyond_those_computed_is_an_argument_error(tmp_path):
    out = tmp_path / "x.png"
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", MODALVIEWER_CACHE=str(tmp_path / "c"))
    args = (ASSETS / "demo_plate.obj", "--operator", "laplacian", "-k", 6, "--mode", 9)
    r = _run(*args, "--screenshot", out, env=env)
    assert r.returncode == 2 and "modalviewer: error: --mode must be between 0 and 5" in r.stderr
    assert not out.exists()


def test_the_window_says_when_its_mode_is_beyond_those_computed():
    from types import SimpleNamespace

    from modalviewer.gui.app import _show_mode

    said, shown = [], []
    window = SimpleNamespace(show_error=said.append, show_mode=shown.append)
    _show_mode(window, SimpleNamespace(k=6), 9)
    assert said == ["--mode 9: the spectrum has modes 0 to 5"] and shown == [5]
    _show_mode(window, SimpleNamespace(k=6), 2)
    assert len(said) == 1 and shown == [5, 2]


def test_every_commands_k_says_its_default():
    # "-k K" was listed without its default (compute and distance 100, batch 50)
    import argparse

    from modalviewer.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    seen = 0
    for name, parser in sub.choices.items():
        for action in parser._actions:
            if "-k" in action.option_strings:
                assert action.help and "default" in action.help, (name, action.help)
                seen += 1
    assert seen >= 4


@pytest.mark.parametrize(
    "argv",
    [
        ["compute", "mesh.obj", "--preview", "-o", "s.npz"],
        ["distance", "mesh.obj", "--vertex", "0", "--preview"],
        ["batch", "folder", "-o", "store", "--preview=yes"],
    ],
    ids=["compute", "distance", "batch"],
)
def test_the_removed_preview_option_is_an_argument_error_saying_what_to_use(argv, capsys):
    """--preview is gone (every spectrum is exact): any command given it exits with code
    2 and one line naming fewer modes and the callback for early modes, before any file
    is read."""
    from modalviewer.cli import main

    _assert_one_argument_error(main, argv, "--preview was removed", capsys)
    _assert_one_argument_error(main, argv, "fewer modes (-k)", capsys)
    _assert_one_argument_error(main, argv, "on_modes=callback", capsys)


def test_compute_says_how_many_modes_are_ready(tmp_path):
    """The progress line counts the modes that have converged while the solve runs."""
    r = _run(
        "compute", ASSETS / "spot.obj", "--operator", "shells", "-k", 60, "-o", tmp_path / "s.npz"
    )
    assert r.returncode == 0, r.stderr
    counts = [int(n) for n in re.findall(r"solving: (\d+) of 60 modes ready", r.stderr)]
    assert len(counts) >= 2 and counts == sorted(counts) and counts[-1] < 60
    assert counts[0] >= 6  # the six rigid motions come with the first modes


def test_a_distance_csv_interrupted_while_written_leaves_the_old_file_whole(
    tmp_path, monkeypatch, capsys
):
    """``distance --csv`` writes beside the target and renames: a run that stops while the
    rows are written (here a full disk after ten rows) is one error line and leaves the
    file it would have replaced as it was, and no temporary file behind."""
    from modalviewer import cli
    from modalviewer.core.mesh import Mesh

    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    csv = tmp_path / "d.csv"
    csv.write_text("vertex,distance\n0,1\n")

    class RowsThenError(np.ndarray):
        def tolist(self):
            rows = super().tolist()
            for i, x in enumerate(rows):
                if i == 10:
                    raise OSError("no space left on device")
                yield x

    def file_field(self, values):
        return np.asarray(values, dtype=float).view(RowsThenError)

    monkeypatch.setattr(Mesh, "to_file_field", file_field)
    args = ["distance", str(ASSETS / "spot.obj"), "--vertex", "0", "--kind", "hks", "-k", "8"]
    assert cli.main([*args, "--csv", str(csv)]) == 1
    assert "modalviewer: error: no space left on device" in capsys.readouterr().err
    assert csv.read_text() == "vertex,distance\n0,1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache", "d.csv"]
