"""The bundled meshes (``assets/``), found in a source checkout and in an installed wheel.

In a checkout (and an editable install) they are the repository's ``assets/`` folder.
A wheel carries them as data files, installed to ``<prefix>/share/modalviewer/assets``
(``<prefix>`` the environment's, or the user scheme's for ``pip install --user``).
"""

from __future__ import annotations

import sys
import sysconfig
from pathlib import Path

_MARKER = "spot.obj"  # the default mesh, present in every copy of the assets


def _candidates() -> list[Path]:
    found = [Path(__file__).resolve().parents[1] / "assets"]
    prefixes = [sys.prefix, sys.base_prefix, sysconfig.get_path("data")]
    try:
        prefixes.append(sysconfig.get_path("data", sysconfig.get_preferred_scheme("user")))
    except (AttributeError, KeyError):  # Python < 3.10 or no user scheme
        pass
    found += [Path(p) / "share" / "modalviewer" / "assets" for p in dict.fromkeys(prefixes) if p]
    return found


def assets_dir() -> Path:
    """The folder of the bundled meshes; a FileNotFoundError naming the places looked in."""
    places = _candidates()
    for place in places:
        if (place / _MARKER).is_file():
            return place
    raise FileNotFoundError(
        "the bundled meshes are not installed; looked in " + ", ".join(map(str, places))
    )


def asset_path(name: str) -> Path:
    """The path of a bundled file (``spot.obj``, ...); a FileNotFoundError lists them."""
    path = assets_dir() / name
    if not path.is_file():
        names = sorted(p.name for p in assets_dir().iterdir() if p.is_file())
        raise FileNotFoundError(f"no bundled file {name!r}; bundled: {', '.join(names)}")
    return path
