"""modalviewer: modal shape analysis beyond the Laplacian.

The public API re-exports the numerical core (numpy/scipy only) and
:class:`~modalviewer.viewer.Viewer`, the viewer without a window (loaded on first use).
Importing this package never imports Qt or VTK; the windows live in ``modalviewer.gui``.
"""

import os as _os

# MKL PARDISO and numpy's OpenBLAS take turns on the same cores hundreds of times per
# eigensolve, and threads left spinning after each call slow the other down; these make
# them sleep soon after each call.  Set before numpy loads OpenBLAS (an explicit setting
# wins); when numpy came first, core/products.py limits OpenBLAS at run time instead.
_os.environ.setdefault("KMP_BLOCKTIME", "0")
_os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")

from .collection import open_collection  # noqa: E402 (numpy only; Dask loads in run_batch)
from .core import *  # noqa: E402, F403
from .core import __all__ as _core_all  # noqa: E402
from .data import asset_path  # noqa: E402
from .extras import MissingExtraError  # noqa: E402
from .interop import as_mesh, operator_matrices, to_pyvista  # noqa: E402
from .io import load_mesh  # noqa: E402
from .plotting import InteractivePicture, Picture, add_to_plotter, plot, view  # noqa: E402
from .repair import SliverReport, fix_slivers  # noqa: E402

__version__ = "0.1.0"
__all__ = [  # noqa: F405
    *_core_all,  # noqa: F405
    "load_mesh",
    "as_mesh",
    "asset_path",
    "MissingExtraError",
    "operator_matrices",
    "to_pyvista",
    "plot",
    "view",
    "add_to_plotter",
    "Picture",
    "InteractivePicture",
    "fix_slivers",
    "SliverReport",
    "Viewer",
    "open_collection",
]


def __getattr__(name):
    if name == "Viewer":  # the viewer's model and jobs load only when asked for
        from .viewer import Viewer

        return Viewer
    raise AttributeError(f"module 'modalviewer' has no attribute {name!r}")
