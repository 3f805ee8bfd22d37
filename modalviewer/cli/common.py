"""What the commands share: the parser, argument types, errors, the progress line,
reading a mesh and reporting what was written."""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from contextlib import contextmanager
from pathlib import Path

import numpy as np

PREVIEW_REMOVED = (
    "--preview was removed: every spectrum is exact. For the lowest modes sooner ask for "
    "fewer modes (-k); from Python, compute_spectrum(..., on_modes=callback) hands over "
    "the lowest exact modes as they converge"
)
"""What any command says to ``--preview`` (an argument error, exit code 2)."""


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2
        if message.startswith("unrecognized arguments:"):
            given = message.split(":", 1)[1].split()
            if any(a == "--preview" or a.startswith("--preview=") for a in given):
                message = PREVIEW_REMOVED
        sys.stderr.write(f"modalviewer: error: {message}\n")
        raise SystemExit(2)


class Unavailable(Exception):
    """An option needing an optional package that is not installed (exit code 2)."""


class BadArgument(ValueError):
    """An argument out of range that only the computation's result shows (``--mode``
    beyond the modes computed): exit code 2, as argparse's own errors."""


# ------------------------------------------------------------------ argument types
def whole(least: int):
    """An argparse type: an integer of at least ``least``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"a whole number is needed, got {text!r}") from None
        if value < least:
            raise argparse.ArgumentTypeError(f"must be at least {least}, got {value}")
        return value

    return parse


def number(low: float = 0.0, low_included: bool = True, high: float = np.inf):
    """An argparse type: a finite number in [low, high] (low excluded unless
    ``low_included``)."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"a number is needed, got {text!r}") from None
        above = value >= low if low_included else value > low
        if not (np.isfinite(value) and above and value <= high):
            where = f"in {'[' if low_included else '('}{low:g}, {high:g}]"
            if not np.isfinite(high):
                where = f"a finite number {'>=' if low_included else '>'} {low:g}"
            raise argparse.ArgumentTypeError(f"must be {where}, got {text}")
        return value

    return parse


COUNT = whole(1)
MODE_INDEX = whole(0)
WEIGHT = number()


def two_numbers(what: str, example: str, least: int, most: float = np.inf):
    """An argparse type: two whole numbers written like ``example`` ("1024x768"), each
    in [least, most]."""

    def parse(text: str) -> tuple[int, int]:
        try:
            a, b = (int(x) for x in text.lower().split("x"))
        except ValueError:
            raise argparse.ArgumentTypeError(f"{what} looks like {example}, got {text!r}") from None
        if not (least <= min(a, b) and max(a, b) <= most):
            bounds = f"at least {least}" if most == np.inf else f"{least} to {most:g}"
            raise argparse.ArgumentTypeError(f"both numbers of {what} must be {bounds}")
        return a, b

    return parse


size = two_numbers("a size", "1024x768", 16, 8192)  # WIDTHxHEIGHT in pixels


def mode_list(text: str) -> list[int]:
    """An argparse type: mode numbers as "1-8", "2,5,9" or both ("0,3-5")."""
    modes = []
    try:
        for part in text.split(","):
            if "-" in part.strip()[1:]:
                lo, hi = (int(x) for x in part.split("-"))
                if hi < lo:
                    raise ValueError
                modes += range(lo, hi + 1)
            else:
                modes.append(int(part))
    except ValueError:
        raise argparse.ArgumentTypeError(f"modes look like 1-8 or 2,5,9, got {text!r}") from None
    if not modes or min(modes) < 0 or len(modes) > 64:
        raise argparse.ArgumentTypeError("modes are 1 to 64 numbers of at least 0")
    return modes


def _view(text: str):
    from ..viewer.camera import parse_view

    try:
        return parse_view(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_camera_arguments(parser) -> None:
    from ..viewer.camera import UP_CHOICES

    parser.add_argument(
        "--up",
        choices=UP_CHOICES,
        default="auto",
        help="the mesh's up axis (auto: +Z where the mesh clearly stands on the XY plane, else +Y)",
    )
    parser.add_argument(
        "--view",
        type=_view,
        default="canonical",
        metavar="VIEW",
        help="camera: canonical (the viewer's first view), +x, -x, +y, -y, +z, -z (from "
        "that side), iso, or AZ,EL (degrees about the up axis and toward it from the front)",
    )


def add_mesh_arguments(parser, slivers_note: str = "") -> None:
    """``--fix-slivers`` and ``--partial``, which every command reading a mesh takes."""
    parser.add_argument(
        "--fix-slivers",
        action="store_true",
        help="first remove needle and cap triangles with modalviewer.fix_slivers (needs "
        "the optional pymeshlab: pip install 'modalviewer[repair]')" + slivers_note,
    )
    parser.add_argument(
        "--partial",
        action="store_true",
        help="read a damaged or truncated file's whole records and say what was dropped "
        "(without it such a file is refused, naming the place of the damage)",
    )


def joined_dash_values(argv: list[str]) -> list[str]:
    """``argv`` with ``--view -x`` written ``--view=-x``: argparse reads a value starting
    with "-" (``--view -x``, ``--view -30,10``, ``--up -z``) as an option unless it is
    joined with "="."""
    out: list[str] = []
    for arg in argv:
        if out and out[-1] in ("--view", "--up") and arg[:1] == "-" and arg[:2] != "--":
            out[-1] += "=" + arg
        else:
            out.append(arg)
    return out


# ------------------------------------------------------------------ progress and warnings
BAR = {"open": False}  # a progress bar line is not finished: an error starts a new one


def progress_bar():
    """``progress(stage, fraction)`` drawing one line on stderr: a new stage at once
    (it may be a long wait), the same stage's progress at most five times a second;
    each stage name is padded to the longest one drawn so far, so a shorter name leaves
    no end of the longer one behind it."""
    state = {"last": 0.0, "width": 20, "stage": None}

    def progress(stage: str, fraction: float) -> None:
        now = time.perf_counter()
        if fraction < 1.0 and stage == state["stage"] and now - state["last"] < 0.2:
            return
        state["last"], state["stage"] = now, stage
        state["width"] = max(state["width"], len(stage))
        filled = int(30 * fraction)
        sys.stderr.write(
            f"\r[{'#' * filled}{'.' * (30 - filled)}] {100 * fraction:5.1f}% "
            f"{stage:<{state['width']}}"
        )
        BAR["open"] = fraction < 1.0
        if fraction >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return progress


@contextmanager
def warnings_printed():
    """Warnings of the core raised inside the block (mv.ZeroModesWarning, ...) printed as
    one ``modalviewer: warning:`` line each on stderr, no source line."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield
        finally:
            for warning in caught:
                sys.stderr.write(f"modalviewer: warning: {warning.message}\n")


# ------------------------------------------------------------------ input and output
def make_output_folders(*outputs: tuple[str, str | None]) -> None:
    """Create the folder of each ``(option, path)`` a command writes (as pictures'
    exports do, :func:`.core.files.make_folder_for`), before any work; an argument
    error (exit code 2) where one cannot be made or written in."""
    from ..core.files import make_folder_for

    for option, path in outputs:
        if path:
            try:
                make_folder_for(Path(path))
            except OSError as exc:
                raise BadArgument(f"{option} {path}: {exc}") from None


def refuse_other_picture_suffix(output) -> None:
    """An argument error for ``-o NAME.jpg`` and the like: pictures are PNG."""
    from ..scene.export import OTHER_PICTURE_SUFFIXES

    if output and Path(output).suffix.lower() in OTHER_PICTURE_SUFFIXES:
        raise BadArgument(f"-o {output}: pictures are written as PNG; give a name ending in .png")


def load(path, fix_slivers: bool = False, partial: bool = False):
    """The mesh read from ``path``; with ``fix_slivers``, repaired by
    :func:`modalviewer.fix_slivers`, whose report is printed.  A damaged or truncated
    file is refused with the place of the damage and the advice of ``--partial``, which
    reads its whole records and prints what was dropped.  The load's report is printed
    where it says more than the mesh's shape."""
    import modalviewer as mv

    from ..core.mesh import MeshError
    from ..readers import DamagedFileError

    if fix_slivers:  # before reading: a missing package is found out at once
        from ..repair import REPAIR_PACKAGES

        module, command = REPAIR_PACKAGES["fix_slivers"]
        try:
            __import__(module)
        except ImportError:
            raise Unavailable(
                f"--fix-slivers needs the optional package {module} (GPL-3.0), which is not "
                f"installed: {command} (or pip install {module})"
            ) from None
    try:
        mesh = mv.load_mesh(path, strict=not partial)
    except DamagedFileError as exc:
        raise MeshError(
            f"{exc.detail}; the file is damaged or truncated: --partial reads its whole records"
        ) from None
    # what loading found and repaired (merged vertices, flipped faces, unused vertices,
    # dropped records): the summary alone is not printed
    if len(mesh.report.messages) > 1 or (partial and mesh.report.messages):
        print(f"{Path(path).name}: {' '.join(mesh.report.messages)}")
    if fix_slivers:
        mesh = mv.fix_slivers(mesh, progress=progress_bar())
        print(f"{Path(path).name}: fix slivers: {' '.join(mesh.report.messages)}")
    return mesh


def viewer_of(mesh, path):
    """A :class:`~modalviewer.viewer.Viewer` showing ``mesh`` (no window, no Qt: its
    pictures are drawn off screen by the same scene the window draws)."""
    from ..viewer import Viewer

    viewer = Viewer()
    viewer.set_mesh(mesh, Path(path))
    return viewer


def picture_text(path) -> str:
    """The picture or animation written: "PNG WxH" (a window has a smallest size), "GIF
    WxH, N frames" or "MP4"."""
    if Path(path).suffix.lower() == ".mp4":
        return "MP4"
    from PIL import Image

    with Image.open(path) as image:
        frames = f", {image.n_frames} frames" if image.format == "GIF" else ""
        return f"{image.format} {image.width}x{image.height}{frames}"


def wrote(path, what: str) -> None:
    """The line every command prints per file it wrote."""
    print(f"wrote {path} ({what})")
