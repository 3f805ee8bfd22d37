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


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, top_level_only: bool):
    """(imported module names) of ``path``, absolute, including relative imports."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    nodes = tree.body if top_level_only else ast.walk(tree)
    found = []
    for node in nodes:
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                prefix = ".".join(base)
                name = f"{prefix}.{node.module}" if node.module else prefix
                if node.module is None:  # from . import a, b
                    found += [f"{prefix}.{alias.name}" for alias in node.names]
                    continue
            else:
                name = node.module
            found.append(name)
            found += [f"{name}.{alias.name}" for alias in node.names]
    return found


def _sources():
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_only_the_windows_import_qt():
    offenders = []
    for path in _sources():
        if _module_name(path).startswith("modalviewer.gui"):
            continue
        for name in _imports(path, top_level_only=False):
            if name.split(".")[0] in QT:
                offenders.append(f"{_module_name(path)} imports {name}")
    assert offenders == []


@pytest.mark.parametrize("layer", sorted(LAYER_FORBIDS))
def test_dependencies_point_one_way(layer):
    offenders = []
    forbidden = tuple(f"modalviewer.{p}" for p in LAYER_FORBIDS[layer])
    for path in _sources():
        module = _module_name(path)
        if not module.startswith(f"modalviewer.{layer}"):
            continue
        for name in _imports(path, top_level_only=True):
            if any(name == f or name.startswith(f + ".") for f in forbidden):
                offenders.append(f"{module} imports {name}")
    assert offenders == []


def test_no_import_cycle_at_load_time():
    modules = {_module_name(p): p for p in _sources()}
    graph = {}
    for module, path in modules.items():
        targets = set()
        for name in _imports(path, top_level_only=True):
            while name and name not in modules:  # "pkg.mod.Class" -> "pkg.mod"
                name = name.rpartition(".")[0]
            if name and name != module and not module.startswith(name + "."):
                targets.add(name)
        graph[module] = targets
    state: dict[str, int] = {}

    def visit(node, path):
        state[node] = 1
        for nxt in sorted(graph[node]):
            # a package's __init__ importing its own submodules is not a cycle
            if nxt.startswith(node + "."):
                continue
            if state.get(nxt) == 1:
                cycle = path[path.index(nxt) :] + [nxt] if nxt in path else [node, nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, [*path, nxt])
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])


def test_the_checker_sees_imports():
    """The parser finds relative and absolute imports (so the tests above can fail)."""
    names = _imports(PACKAGE / "gui" / "main_window.py", top_level_only=True)
    assert "qtpy" in names and "modalviewer.viewer.viewer" in names
