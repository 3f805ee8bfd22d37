"""The gallery: every script of examples/gallery runs from the installed wheel and writes
at least one PNG with a picture in it, and the docs extension re-runs a script only when
its text changed."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import gallery  # noqa: E402

SCRIPTS = gallery.scripts()


def drawn_share(path: Path) -> float:
    """The share of the picture's pixels that are not (near) white background."""
    from PIL import Image

    rgb = np.asarray(Image.open(path).convert("RGB"), dtype=np.int16)
    return float((rgb.min(axis=2) < 235).mean())


def test_gallery_has_five_to_nine_short_scripts_with_a_title_and_text():
    assert 5 <= len(SCRIPTS) <= 9, [p.name for p in SCRIPTS]
    for script in SCRIPTS:
        doc, code = gallery.split(script.read_text())
        title, underline, blank, *text = doc.splitlines()
        assert set(underline) == {"="} and len(underline) >= len(title), script.name
        assert not blank.strip() and " ".join(text).count(".") >= 1, script.name
        assert len(code.splitlines()) <= 40, script.name
        assert "import modalviewer as mv" in code, script.name


@pytest.fixture(scope="module")
def spectrum_cache(tmp_path_factory):
    """One empty spectrum cache for the module: each script computes its spectra."""
    return tmp_path_factory.mktemp("spectra")


@pytest.mark.parametrize("script", SCRIPTS, ids=[p.stem for p in SCRIPTS])
def test_gallery_script_runs_from_the_installed_wheel_and_writes_a_picture(
    script, tmp_path, spectrum_cache, installed_wheel
):
    """A copy of the script, run in a folder outside the checkout by the Python of a
    fresh environment with the wheel installed (``installed_wheel``): its meshes must
    come from the wheel (``mv.asset_path``), not from a path next to the package's
    source.  It writes at least one PNG, and every picture it writes has a drawing in it."""
    _, python, _ = installed_wheel
    shutil.copy(script, tmp_path / script.name)
    env = dict(os.environ, MODALVIEWER_CACHE=str(spectrum_cache), QT_QPA_PLATFORM="offscreen")
    env.pop("PYTHONPATH", None)
    result = subprocess.run(
        [python, script.name],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    pngs = gallery.pictures(tmp_path)
    assert any(p.suffix == ".png" for p in pngs), f"{script.name} wrote no PNG"
    for png in pngs:
        assert png.stat().st_size > 1000, png.name
        share = drawn_share(png)
        assert share > 0.03, f"{png.name}: only {share:.1%} of the pixels are drawn"


def test_extension_runs_a_script_again_only_when_it_changed(tmp_path):
    script = tmp_path / "tiny.py"
    script.write_text(
        '"""A tiny example\n================\n\nIt writes a grey square.\n"""\n\n'
        "import numpy as np\nfrom PIL import Image\n\n"
        'Image.fromarray(np.full((8, 8, 3), 90, np.uint8)).save("tiny.png")\nprint("done")\n'
    )
    out = tmp_path / "out"
    first = gallery.run(script, out)
    assert first.error is None and first.seconds is not None
    assert [p.name for p in first.images] == ["tiny.png"] and first.output == "done\n"
    again = gallery.run(script, out)
    assert again.seconds is None and [p.name for p in again.images] == ["tiny.png"]
    script.write_text(script.read_text().replace("90", "91"))
    assert gallery.run(script, out).seconds is not None
    page = gallery.page_source([again], docs=tmp_path)
    assert "A tiny example\n================" in page
    assert ".. code-block:: python" in page and "   import numpy as np" in page
    assert ".. image:: out/tiny/tiny.png" in page and "It prints:" in page


def test_a_failing_script_is_reported(tmp_path):
    script = tmp_path / "broken.py"
    script.write_text('"""Broken\n======\n\nIt fails.\n"""\n\nraise SystemExit(3)\n')
    example = gallery.run(script, tmp_path / "out")
    assert example.error is not None and "exit status 3" in example.error
    assert not (tmp_path / "out" / "broken" / "hash").exists()
