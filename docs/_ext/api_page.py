"""The API reference's source, written at build time from ``modalviewer.__all__``.

``conf.py`` calls :func:`write_api_page`, which writes ``docs/_generated/api.inc``; that
file is included by ``docs/api.rst``.  Every name the package exports gets an autodoc
directive, grouped by the module that defines it (in the order of ``__all__``), so a newly
exported name appears in the reference without editing the docs.  The viewer's
``Viewer`` class is added when it can be imported.
"""

from __future__ import annotations

import importlib
import inspect
import sys
from pathlib import Path

#: Classes documented beside the package's ``__all__`` when importable: (module, name).
OPTIONAL = [("modalviewer.viewer", "Viewer"), ("modalviewer.viewer.viewer", "Viewer")]


def _directive(obj) -> str:
    if inspect.isclass(obj):
        return "autoexception" if issubclass(obj, BaseException) else "autoclass"
    if callable(obj):
        return "autofunction"
    return "autodata"


def _options(directive: str, name: str = "") -> list[str]:
    if directive in ("autoclass", "autoexception"):
        # the Viewer is its model and its pictures: their methods are its own
        inherited = ["   :inherited-members:"] if name == "Viewer" else []
        return ["   :members:", "   :show-inheritance:", *inherited]
    if directive == "autodata":
        return ["   :annotation:"]
    return []


def _module_summary(module_name: str) -> str:
    """The first paragraph of the module's docstring."""
    module = importlib.import_module(module_name)
    return (inspect.getdoc(module) or "").strip().split("\n\n")[0]


def _heading(text: str, char: str) -> list[str]:
    return [text, char * len(text), ""]


def _section(module_name: str, entries: list[tuple[str, str]], public: str) -> list[str]:
    lines = _heading(module_name, "-")
    summary = _module_summary(module_name)
    if summary:
        lines += [summary, ""]
    lines += [f".. currentmodule:: {public}", ""]
    for directive, name in entries:
        lines += [f".. {directive}:: {name}", *_options(directive, name), ""]
    return lines


def optional_classes(exported=()) -> list[tuple[str, object]]:
    """The OPTIONAL classes that import now, as (public module, class); one per name, none
    of the names in ``exported`` (those are documented as ``modalviewer.<name>``)."""
    found, names = [], set(exported)
    for module_name, name in OPTIONAL:
        if name in names:
            continue
        try:
            obj = getattr(importlib.import_module(module_name), name)
        except (ImportError, AttributeError):
            continue
        found.append((module_name, obj))
        names.add(name)
    return found


def api_source() -> str:
    """reStructuredText documenting every name of ``modalviewer.__all__`` (and Viewer)."""
    import modalviewer

    groups: dict[str, list[tuple[str, str]]] = {}
    for name in modalviewer.__all__:
        try:
            obj = getattr(modalviewer, name)
        except ImportError:
            # A name loaded on first use whose module does not import now: listed all the
            # same (autodoc then reports the import error, which fails the -W build).
            directive = "autoclass" if name[:1].isupper() else "autofunction"
            groups.setdefault("modalviewer", []).append((directive, name))
            continue
        module = getattr(obj, "__module__", None) if not isinstance(obj, tuple) else None
        if not module or not module.startswith("modalviewer"):
            # data such as OPERATORS: the module that assigns it
            module = _defining_module(name)
        groups.setdefault(module, []).append((_directive(obj), name))
    lines = [".. This file is written by docs/_ext/api_page.py at build time; do not edit.", ""]
    for module_name, entries in groups.items():
        lines += _section(module_name, entries, "modalviewer")
    viewer = optional_classes(modalviewer.__all__)
    if viewer:
        lines += _heading("The viewer", "-")
        for module_name, obj in viewer:
            lines += [f".. currentmodule:: {module_name}", ""]
            lines += [f".. autoclass:: {obj.__name__}", *_options("autoclass", obj.__name__), ""]
    return "\n".join(lines).rstrip() + "\n"


def _defining_module(name: str) -> str:
    """The submodule of modalviewer.core (or the package) whose namespace defines ``name``."""
    import modalviewer
    import modalviewer.core as core

    for module_name in sorted(m for m in _loaded() if m.startswith("modalviewer.core.")):
        module = importlib.import_module(module_name)
        if name in vars(module) and vars(module)[name] is getattr(core, name, None):
            source = getattr(module, "__all__", None)
            if source is None or name in source:
                return module_name
    return modalviewer.__name__


def _loaded() -> list[str]:
    return list(sys.modules)


def write_api_page(path: Path) -> bool:
    """Write :func:`api_source` to ``path`` if it changed; True when it was written."""
    text = api_source()
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.is_file() and path.read_text() == text:
        return False
    path.write_text(text)
    return True
