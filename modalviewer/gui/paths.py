"""Folders the viewer uses: the bundled meshes (:func:`modalviewer.data.assets_dir`) and
screenshots (the checkout's ``screenshots/``, else ``screenshots/`` in the current
folder).
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
