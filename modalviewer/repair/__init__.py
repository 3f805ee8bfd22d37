"""Mesh repairs: which there are (:data:`REPAIRS`), what each needs and how to apply one,
for the viewer, the command line and the child processes.  The repairs every file gets
on loading are :func:`modalviewer.core.cleaning.repair_mesh`'s."""

from __future__ import annotations

from ..core.mesh import Mesh
from .slivers import SliverReport, fix_slivers

__all__ = [
    "REPAIRS",
    "REPAIR_PACKAGES",
    "SliverReport",
    "apply_repair",
    "fix_slivers",
    "repair_for_failure",
    "repair_unavailable",
]

REPAIRS = {
    "fix_slivers": "Fix slivers (edge flips and collapses)",
    "largest_component": "Keep the largest component",
}
"""Repairs the viewer offers on a loaded mesh, with their names in words."""

REPAIR_PACKAGES = {"fix_slivers": ("pymeshlab", "pip install 'modalviewer[repair]'")}
"""Repairs needing an optional package: (module, the command installing it; the
``repair`` extra of pyproject.toml)."""


def repair_for_failure(error: str | None) -> str | None:
    """The repair (a name of :data:`REPAIRS`) that may let a computation which failed with
    ``error`` succeed: "fix_slivers" where the operator could not be factorised on nearly
    degenerate (sliver) triangles; None otherwise."""
    text = (error or "").lower()
    if "could not be factorised" in text and "sliver" in text:
        return "fix_slivers"
    return None


def repair_unavailable(name: str) -> str | None:
    """Why repair ``name`` cannot run here and how to install what it needs (None if it
    can).  The package is looked up, not imported (pymeshlab runs in a child process)."""
    if name not in REPAIR_PACKAGES:
        return None
    import importlib.util

    module, command = REPAIR_PACKAGES[name]
    importlib.invalidate_caches()  # installed since the viewer started: found now
    try:
        found = importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        found = False
    if found:
        return None
    return (
        f"{REPAIRS[name]} needs the optional package {module} (GPL-3.0), which is not "
        f"installed. Install it with\n\n    {command}\n\n(or pip install {module}) in "
        "the Python environment of modalviewer, then try again; no restart is needed."
    )


def apply_repair(name: str, mesh: Mesh, progress=None) -> Mesh:
    """Repair ``name`` applied to ``mesh`` (a new Mesh whose report says what changed)."""
    if name == "fix_slivers":
        return fix_slivers(mesh, progress=progress)
    if name == "largest_component":
        from ..core.components import largest_component

        return largest_component(mesh)
    raise ValueError(f"unknown repair {name!r}")
