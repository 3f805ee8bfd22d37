"""The command line's camera: ``render`` and ``distance -o`` take --up and --view."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import modalviewer as mv

ASSETS = Path(__file__).resolve().parents[1] / "assets"


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "modalviewer", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.fixture(scope="module")
def z_up_cow(tmp_path_factory):
    """spot turned to Z-up (a quarter turn about X)."""
    mesh = mv.load_mesh(ASSETS / "spot.obj")
    v = mesh.vertices
    v = np.column_stack([v[:, 0], -v[:, 2], v[:, 1]])
    path = tmp_path_factory.mktemp("zup") / "spot_z_up.obj"
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh.faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def _render(mesh, out, *extra):
    r = _run("render", mesh, "--mode", 2, "-k", 6, "--size", "160x120", "-o", out, *extra)
    assert r.returncode == 0, r.stderr
    return np.asarray(Image.open(out).convert("L"), dtype=float)


def _differ(a, b):
    return float(np.mean(np.abs(a - b) > 30))


def test_up_and_view_change_the_picture(z_up_cow, tmp_path):
    auto = _render(z_up_cow, tmp_path / "auto.png")
    explicit = _render(z_up_cow, tmp_path / "z.png", "--up", "+z")
    y_up = _render(z_up_cow, tmp_path / "y.png", "--up", "+y")
    side = _render(z_up_cow, tmp_path / "side.png", "--view", "+y")
    angled = _render(z_up_cow, tmp_path / "angled.png", "--view", "90,20")
    assert _differ(auto, explicit) < 0.001  # auto found +Z
    assert _differ(auto, y_up) > 0.02
    assert _differ(auto, side) > 0.02
    assert _differ(side, angled) > 0.02
    # values starting with "-" need no "=": --view -y, --up -z (argparse read them as options)
    below = _render(z_up_cow, tmp_path / "below.png", "--view", "-y", "--up", "-z")
    joined = _render(z_up_cow, tmp_path / "joined.png", "--view=-y", "--up=-z")
    assert _differ(below, joined) == 0.0 and _differ(below, side) > 0.02


def test_distance_takes_the_view_too(tmp_path):
    common = ("distance", ASSETS / "demo_machined_part.obj", "--vertex", 5, "--kind", "hks")
    common += ("-k", 10, "--size", "160x120")
    pictures = []
    for view in ("canonical", "iso", "+y"):
        out = tmp_path / f"{view}.png"
        r = _run(*common, "-o", out, "--view", view)
        assert r.returncode == 0, r.stderr
        pictures.append(np.asarray(Image.open(out).convert("L"), dtype=float))
    assert _differ(pictures[0], pictures[1]) > 0.02
    assert _differ(pictures[1], pictures[2]) > 0.02


@pytest.mark.parametrize(
    "args, message",
    [
        (("--view", "top"), "unknown view 'top'"),
        (("--view", "10,95"), "unknown view"),
        (("--up", "z"), "invalid choice: 'z'"),
    ],
)
def test_bad_views_and_up_axes_are_one_line_errors(args, message, tmp_path):
    r = _run("render", ASSETS / "demo_plate.obj", "--mode", 1, "-o", tmp_path / "x.png", *args)
    assert r.returncode == 2
    errors = [line for line in r.stderr.splitlines() if line.startswith("modalviewer: error")]
    assert len(errors) == 1 and message in errors[0], r.stderr


def test_distance_to_a_second_mesh_refuses_up_and_view(tmp_path, capsys):
    """The two-mesh picture turns each panel to its marker: --up/--view are refused there
    with a one-line error instead of being ignored."""
    from modalviewer import cli

    spot = str(Path(__file__).resolve().parents[1] / "assets" / "spot.obj")
    code = cli.main(["distance", spot, "--vertex", "5", "--to", spot, "--view", "+x", "-k", "10"])
    err = capsys.readouterr().err
    assert code == 1 and "--up and --view apply to one mesh" in err


def test_a_scene_of_a_mesh_alone_stands_a_z_up_mesh_upright(z_up_cow):
    # the two-mesh distance figure, the pair window and notebook plots make a scene
    # without the viewer's state: its up axis is then the one Automatic finds (it was
    # +Y, so a Z-up scan was drawn lying on its back, seen from below)
    from modalviewer.core.laplacian import vertex_normals
    from modalviewer.scene.mesh_scene import MeshScene
    from modalviewer.scene.offscreen import offscreen_plotter

    upright = mv.load_mesh(ASSETS / "spot.obj")
    lying = mv.load_mesh(z_up_cow)
    for mesh, axis in ((upright, 1), (lying, 2)):
        plotter = offscreen_plotter((160, 120))
        try:
            scene = MeshScene(plotter, mesh, vertex_normals(mesh))
            up = np.asarray(scene.canonical_camera().up)
            assert up[axis] > 0.9, up
            scene.up_axis = "+x"  # a chosen axis still wins
            assert np.asarray(scene.canonical_camera().up)[0] > 0.9
        finally:
            plotter.close()
