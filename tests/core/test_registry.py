"""The operator registry holds every per-operator fact, and the core stands alone.

- No module of the package outside ``core/operators.py`` compares to, or keys on, an
  operator's name: a new operator is one registry entry.  Docstrings, help texts and
  arguments (``compute("shells")``) may name operators; comparisons, ``in`` tests,
  ``startswith``, dict keys and subscripts may not.
- Importing the numerical core imports neither the viewer, the windows, the drawing,
  Qt nor VTK.
- The modules of ``modalviewer.core`` import each other without a cycle (every import
  counts, also those inside functions).
"""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

from modalviewer.core import operators
from modalviewer.core.operators import (
    DISTANCE_KINDS,
    NULL_SPACE_RULES,
    OPERATOR_INFO,
    OPERATOR_NAMES,
)

PACKAGE = Path(operators.__file__).resolve().parents[1]
CORE = PACKAGE / "core"
REGISTRY = CORE / "operators.py"
FORBIDDEN = ("modalviewer.viewer", "modalviewer.gui", "modalviewer.scene", "qtpy", "pyvista", "vtk")


def _sources(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*.py") if "__pycache__" not in p.parts)


def _is_name(node: ast.AST) -> bool:
    return isinstance(node, ast.Constant) and node.value in OPERATOR_NAMES


def _names_in(node: ast.AST) -> bool:
    """An operator name, or a tuple / list / set literal holding one."""
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return any(_is_name(e) for e in node.elts)
    return _is_name(node)


def operator_name_uses(source: str) -> list[tuple[int, str]]:
    """(line, what) for every comparison with, key of or subscript by an operator name."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            if any(_names_in(side) for side in [node.left, *node.comparators]):
                found.append((node.lineno, "comparison"))
        elif isinstance(node, ast.Dict):
            if any(key is not None and _is_name(key) for key in node.keys):
                found.append((node.lineno, "dict key"))
        elif isinstance(node, ast.Subscript):
            if _is_name(node.slice):
                found.append((node.lineno, "subscript"))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
            if node.func.attr in ("startswith", "endswith") and any(map(_names_in, node.args)):
                found.append((node.lineno, node.func.attr))
        elif isinstance(node, ast.match_case) and isinstance(node.pattern, ast.MatchValue):
            if _is_name(node.pattern.value):
                found.append((node.pattern.lineno, "match case"))
    return found


def test_the_checker_finds_what_it_looks_for():
    source = (
        '"""shells"""\n'
        'a = x == "shells"\n'
        'b = x in ("laplacian", "shells")\n'
        'c = {"shells": 3}\n'
        'd = y["laplacian"]\n'
        'e = x.startswith("shells")\n'
        'f(x, "shells", help="shells")\n'
    )
    assert [line for line, _ in operator_name_uses(source)] == [2, 3, 4, 5, 6]


def test_no_module_outside_the_registry_compares_to_an_operator_name():
    offences = [
        f"{path.relative_to(PACKAGE.parent)}:{line}: {what}"
        for path in _sources(PACKAGE)
        if path != REGISTRY
        for line, what in operator_name_uses(path.read_text(encoding="utf-8"))
    ]
    assert not offences, "ask core.operators instead:\n" + "\n".join(offences)


@pytest.mark.parametrize("name", OPERATOR_NAMES)
def test_every_registry_entry_is_complete(name):
    info = OPERATOR_INFO[name]
    assert info.name == name
    assert info.unknowns_per_vertex in (1, 3)
    assert info.null_space_rule in NULL_SPACE_RULES
    assert info.null_space
    assert info.distance_kind is None or info.distance_kind in DISTANCE_KINDS
    assert (info.signature_word is None) == (info.distance_kind is None)
    assert info.exact_growth.peak_mb_at_100k > 0
    module, function = info.assemble.split(":")
    assert callable(getattr(importlib.import_module(f"modalviewer.core.{module}"), function))


def test_each_distance_kind_belongs_to_one_operator():
    kinds = [
        kind
        for i in OPERATOR_INFO.values()
        for kind in (i.distance_kind, i.wave_distance_kind)
        if kind
    ]
    assert sorted(kinds) == sorted(DISTANCE_KINDS)
    assert operators.distance_word("hks") == "heat kernel"
    assert operators.distance_word("wks") == "wave kernel"
    assert operators.operator_for_distance("wks") == "laplacian"
    assert [operators.signature_kind(k) for k in ("hks", "feature", "vibration", "wks")] == [
        "heat",
        "heat",
        "heat",
        "wks",
    ]


def test_importing_the_core_imports_no_viewer_gui_qt_or_vtk():
    """Every core module (and every assembly function the registry names) is imported in
    one fresh interpreter: what none of them imports together, none imports alone."""
    modules = [f"modalviewer.core.{p.stem}" for p in _sources(CORE) if p.stem != "__init__"]
    script = (
        "import importlib, sys\n"
        f"for name in {modules!r}:\n"
        "    importlib.import_module(name)\n"
        "from modalviewer.core.operators import OPERATOR_INFO\n"
        "for info in OPERATOR_INFO.values():\n"
        "    module, function = info.assemble.split(':')\n"
        "    getattr(importlib.import_module('modalviewer.core.' + module), function)\n"
        f"bad = sorted(m for m in sys.modules if m.split('.')[0] in {FORBIDDEN!r}\n"
        f"             or m.startswith({FORBIDDEN!r}))\n"
        "print('\\n'.join(bad))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
        cwd=PACKAGE.parent,
    )
    assert out.stdout.strip() == "", f"the core imports: {out.stdout.split()}"


def _core_imports(path: Path, known: set[str]) -> set[str]:
    """Core modules that ``path`` imports anywhere (module level or inside functions)."""
    package = "modalviewer.core"
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                base = f"{base}.{node.module}" if node.module else base
            else:
                base = node.module or ""
            # ``from . import x`` names module x; ``from .x import y`` module x (or x.y)
            targets = [f"{base}.{alias.name}" for alias in node.names]
            targets = [t for t in targets if t in known] or [base]
        else:
            continue
        found.update(t for t in targets if t in known)
    return found


def test_the_core_modules_import_each_other_without_a_cycle():
    names = {
        p: "modalviewer.core" + ("" if p.stem == "__init__" else f".{p.stem}")
        for p in _sources(CORE)
    }
    known = set(names.values())
    graph = {name: _core_imports(path, known) - {name} for path, name in names.items()}
    # the package's __init__ gathers the modules' names; no module may import it
    importers = sorted(n for n, deps in graph.items() if "modalviewer.core" in deps)
    assert not importers, f"these import modalviewer.core itself: {importers}"
    done: set[str] = set()

    def visit(node: str, path: list[str]) -> None:
        if node in path:
            cycle = path[path.index(node) :] + [node]
            pytest.fail("import cycle: " + " -> ".join(cycle))
        if node in done:
            return
        for dep in sorted(graph[node]):
            visit(dep, path + [node])
        done.add(node)

    for name in sorted(graph):
        visit(name, [])
