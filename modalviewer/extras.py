"""Optional dependencies: ``import modalviewer`` needs numpy and scipy only; a call that
needs a missing package raises :class:`MissingExtraError` naming the extra to install."""

from __future__ import annotations

from contextlib import contextmanager

EXTRA_OF = {
    "pyvista": "viewer",
    "vtk": "viewer",
    "vtkmodules": "viewer",
    "qtpy": "viewer",
    "PySide6": "viewer",
    "pyvistaqt": "viewer",
    "matplotlib": "viewer",
    "PIL": "viewer",
    "meshio": "meshio",
    "pymeshlab": "repair",
    "fast_simplification": "repair",
    "dask": "batch",
    "distributed": "batch",
    "trame_pyvista": "notebook",
    "trame_vtk": "notebook",
    "robust_laplacian": "robust",
    "imageio": "video",
    "imageio_ffmpeg": "video",
}
"""The top-level module of each optional package and the extra that installs it."""


class MissingExtraError(ModuleNotFoundError):
    """An optional package is missing; the message names the extra that installs it."""


@contextmanager
def extra_needed(what: str):
    """Run the block; an optional package it fails to import becomes a
    :class:`MissingExtraError` saying that ``what`` needs it and how to install it."""
    try:
        yield
    except MissingExtraError:
        raise
    except ModuleNotFoundError as exc:
        top = (exc.name or "").split(".")[0]
        if top not in EXTRA_OF:
            raise
        raise MissingExtraError(
            f"{what} needs {top}, which is not installed: "
            f'pip install "modalviewer[{EXTRA_OF[top]}]"',
            name=top,
        ) from None
