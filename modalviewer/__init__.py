"""modalviewer: modal shape analysis beyond the Laplacian.

The public API re-exports the numerical core (numpy/scipy only).  Importing this
package never imports Qt or VTK; the viewer lives in ``modalviewer.gui``.

>>> import modalviewer as mv
>>> mesh = mv.load_mesh("assets/bumpy_plate.obj")          # doctest: +SKIP
>>> spec = mv.compute_spectrum(mesh, "modified_dirichlet", k=50)  # doctest: +SKIP
"""

from .core import *  # noqa: F403
from .core import __all__ as _core_all
from .io import load_mesh

__version__ = "0.1.0"
__all__ = [*_core_all, "load_mesh"]
