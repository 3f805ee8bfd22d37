"""Folders the viewer uses: the bundled meshes and screenshots.

The bundled meshes come from :func:`modalviewer.data.assets_dir` (the checkout's
``assets/`` or the wheel's data files).  Screenshots go to the checkout's
``screenshots/`` in a checkout, to ``screenshots/`` in the current folder otherwise.
"""

from pathlib import Path

from ..data import assets_dir

_CHECKOUT = Path(__file__).resolve().parents[2]

try:
    ASSETS = assets_dir()
except FileNotFoundError:  # an install without its data files: the dialogs start here
    ASSETS = _CHECKOUT / "assets"
DEFAULT_MESH = ASSETS / "spot.obj"
SCREENSHOTS = (
    _CHECKOUT / "screenshots" if (_CHECKOUT / "pyproject.toml").is_file() else Path("screenshots")
)
