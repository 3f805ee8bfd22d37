"""Notebooks run in a Jupyter kernel: examples/quickstart.ipynb from top to bottom with
its pictures, and the desktop viewer opened from a kernel."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "examples" / "quickstart.ipynb"


def _executed(nb_or_cells, tmp_path, monkeypatch):
    """The notebook (a path's, or one made of code cells) executed in a fresh kernel
    off screen, with its own spectrum cache; skipped without the notebook tools."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    pytest.importorskip("pyvista")
    monkeypatch.setenv("MODALVIEWER_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("QT_QPA_PLATFORM", "offscreen")
    if isinstance(nb_or_cells, Path):
        nb = nbformat.read(nb_or_cells, as_version=4)
    else:
        nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in nb_or_cells])
    client = nbclient.NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    return nb


def test_the_quickstart_notebook_executes(tmp_path, monkeypatch):
    nb = _executed(NOTEBOOK, tmp_path, monkeypatch)
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    pictures = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(pictures) >= 3
    text = "".join(o.get("text", "") for o in outputs)
    assert "best match: vertex" in text


def test_the_desktop_viewer_opens_from_a_notebook_kernel(tmp_path, monkeypatch):
    # mv.view(..., block=False) in a Jupyter kernel: pyvista took the viewer's off-screen
    # plotters for notebook plots and raised "Notebook plotting requires 'anywidget'"
    cells = [
        "import modalviewer as mv\n"
        f"mesh = mv.load_mesh({str(ROOT / 'assets' / 'spot.obj')!r})\n"
        "spec = mv.compute_spectrum(mesh, 'laplacian', k=12)",
        "window = mv.view(mesh, spec, fields={'height': mesh.vertices[:, 1]}, block=False)\n"
        "print(type(window).__name__, window.viewer.current_field()[0])",
        "print(window.viewer.image().shape[2]); window.close()",
    ]
    nb = _executed(cells, tmp_path, monkeypatch)
    outputs = [o for c in nb.cells for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"], outputs
    text = "".join(o.get("text", "") for o in outputs)
    assert "MainWindow height" in text and "\n3\n" in f"\n{text}"
