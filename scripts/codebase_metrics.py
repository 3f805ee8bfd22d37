"""Print the size and shape figures the project holds itself to, read from the sources.

    python scripts/codebase_metrics.py            # the figures and what breaks a limit
    python scripts/codebase_metrics.py --check    # exit status 1 if any limit is broken

Figures: lines in ``modalviewer/``; import circles among its modules (imports at module
level and inside functions both count; a package importing its own submodules does not);
functions over 120 lines; modules over 800 lines; docstring lines that cite a measurement
(seconds, megabytes, percentages or speed-up factors from a particular run).
"""

from __future__ import annotations

import argparse
import ast
import re
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "modalviewer"

LIMITS = {
    "lines": 19_500,
    "import circles": 0,
    "functions over 120 lines": 0,
    "modules over 800 lines": 0,
    "docstring lines citing a measurement": 10,
}
LONG_FUNCTION = 120
LONG_MODULE = 800

# a number followed by a unit of time, memory, a percentage or a speed-up factor
MEASUREMENT = re.compile(
    r"\b\d+(?:[.,]\d+)?\s*(?:s|ms|min|seconds?|minutes?|MB|GB|MiB|GiB|kB|%|x faster|times faster)"
    r"(?![A-Za-z])"
)


def sources() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_names(path: Path, tree: ast.AST, top_level_only: bool = False) -> list[str]:
    """The absolute names ``path`` imports (``tree`` is its parse): modules, and
    ``module.name`` for each name taken from one; relative imports resolved.  With
    ``top_level_only``, only the imports run when the module loads."""
    module = module_name(path)
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    found = []
    for node in tree.body if top_level_only else ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                prefix = ".".join(base[: len(base) - node.level + 1])
                if node.module is None:  # from . import a, b
                    found += [f"{prefix}.{alias.name}" for alias in node.names]
                    continue
                name = f"{prefix}.{node.module}"
            else:
                name = node.module or ""
            found.append(name)
            found += [f"{name}.{alias.name}" for alias in node.names]
    return found


def import_graph(trees: dict[Path, ast.AST], top_level_only: bool = False) -> dict[str, set[str]]:
    """Which of the package's modules each module imports (see :func:`imported_names`)."""
    modules = {module_name(p): p for p in trees}
    graph: dict[str, set[str]] = {}
    for module, path in modules.items():
        targets = set()
        for name in imported_names(path, trees[path], top_level_only):
            while name and name not in modules:  # "pkg.mod.Class" -> "pkg.mod"
                name = name.rpartition(".")[0]
            if not name or name == module:
                continue
            # a package and its own submodules: __init__ re-exporting them is no circle
            if name.startswith(module + ".") or module.startswith(name + "."):
                continue
            targets.add(name)
        graph[module] = targets
    return graph


def import_circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[list[str]] = []

    def connect(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(graph[node]):
            if nxt not in index:
                connect(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            component = []
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.append(top)
                if top == node:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    sys.setrecursionlimit(10_000)
    for node in sorted(graph):
        if node not in index:
            connect(node)
    return circles


def long_functions(trees: dict[Path, ast.AST]) -> list[tuple[str, int]]:
    found = []
    for path, tree in trees.items():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > LONG_FUNCTION:
                    found.append((f"{module_name(path)}.{node.name}", length))
    return sorted(found, key=lambda item: -item[1])


def docstring_measurements(trees: dict[Path, ast.AST]) -> list[tuple[str, str]]:
    found = []
    for path, tree in trees.items():
        for node in ast.walk(tree):
            if not isinstance(
                node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)
            ):
                continue
            doc = ast.get_docstring(node, clean=False)
            if not doc:
                continue
            where = module_name(path) + ("" if isinstance(node, ast.Module) else f".{node.name}")
            found += [
                (where, line.strip()) for line in doc.splitlines() if MEASUREMENT.search(line)
            ]
    return found


def measure() -> dict:
    paths = sources()
    texts = {p: p.read_text(encoding="utf-8") for p in paths}
    trees = {p: ast.parse(texts[p]) for p in paths}
    lengths = {module_name(p): len(texts[p].splitlines()) for p in paths}
    return {
        "lines": sum(lengths.values()),
        "import circles": import_circles(import_graph(trees)),
        "functions over 120 lines": long_functions(trees),
        "modules over 800 lines": sorted(
            ((m, n) for m, n in lengths.items() if n > LONG_MODULE), key=lambda item: -item[1]
        ),
        "docstring lines citing a measurement": docstring_measurements(trees),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a limit is broken")
    args = parser.parse_args(argv)
    figures = measure()
    broken = 0
    for name, limit in LIMITS.items():
        value = figures[name]
        count = value if isinstance(value, int) else len(value)
        over = count > limit
        broken += over
        print(f"{name:40s} {count:>7,d}   (limit {limit:,d}){'   OVER' if over else ''}")
        if not isinstance(value, int):
            for item in value:
                if isinstance(item, list):
                    print("    " + " <-> ".join(item))
                else:
                    print(f"    {item[0]}: {item[1]}")
    return 1 if (args.check and broken) else 0


if __name__ == "__main__":
    sys.exit(main())
