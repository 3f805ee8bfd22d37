"""Folders of the source tree the viewer uses: bundled meshes and screenshots."""

from pathlib import Path

ASSETS = Path(__file__).resolve().parents[2] / "assets"
DEFAULT_MESH = ASSETS / "spot.obj"
SCREENSHOTS = Path(__file__).resolve().parents[2] / "screenshots"
