"""The package's layers, read from its sources: dependencies point one way,
``gui -> scene -> viewer -> core`` (and ``cli -> viewer``), only ``gui`` imports Qt,
and no two modules import each other at load time.

Imports inside functions count for the Qt rule (Qt must never be reached outside the
windows) but not for the layers: the viewer loads ``modalviewer.scene`` inside
``Viewer.export_screenshot`` and friends, only when a picture is asked for.
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "modalviewer"
QT = ("qtpy", "PySide6", "PyQt5", "PyQt6", "pyvistaqt", "shiboken6")

LAYER_FORBIDS = {
    # layer: packages its modules must not import at load time
    "core": ("viewer", "scene", "gui", "cli", "figures", "processes", "repair", "io"),
    "viewer": ("scene", "gui", "cli", "figures"),
    "scene": ("gui", "cli", "figures"),
    "processes": ("gui", "scene"),
    "repair": ("viewer", "scene", "gui"),
}


@pytest.fixture(scope="module")
def trees(codebase_metrics):
    """Each source file of the package and its parse."""
    return {p: ast.parse(p.read_text(encoding="utf-8")) for p in codebase_metrics.sources()}


def test_only_the_windows_import_qt(codebase_metrics, trees):
    offenders = []
    for path, tree in trees.items():
        module = codebase_metrics.module_name(path)
        if module.startswith("modalviewer.gui"):
            continue
        for name in codebase_metrics.imported_names(path, tree):
            if name.split(".")[0] in QT:
                offenders.append(f"{module} imports {name}")
    assert offenders == []


@pytest.mark.parametrize("layer", sorted(LAYER_FORBIDS))
def test_dependencies_point_one_way(layer, codebase_metrics, trees):
    offenders = []
    forbidden = tuple(f"modalviewer.{p}" for p in LAYER_FORBIDS[layer])
    for path, tree in trees.items():
        module = codebase_metrics.module_name(path)
        if not module.startswith(f"modalviewer.{layer}"):
            continue
        for name in codebase_metrics.imported_names(path, tree, top_level_only=True):
            if any(name == f or name.startswith(f + ".") for f in forbidden):
                offenders.append(f"{module} imports {name}")
    assert offenders == []


def test_no_import_cycle_at_load_time(codebase_metrics, trees):
    graph = codebase_metrics.import_graph(trees, top_level_only=True)
    assert codebase_metrics.import_circles(graph) == []


def test_the_checker_sees_imports(codebase_metrics, trees):
    """The parser finds relative and absolute imports (so the tests above can fail)."""
    path = PACKAGE / "gui" / "main_window.py"
    names = codebase_metrics.imported_names(path, trees[path], top_level_only=True)
    assert "qtpy" in names and "modalviewer.viewer.viewer" in names
