"""Headless commands: ``modalviewer compute | render | distance``.

Bad arguments and bad files give a one-line error and exit code 2 (usage) or 1
(input or computation), never a traceback.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from .core.operators import (
    DEFAULT_K,
    DISTANCE_KINDS,
    OPERATOR_NAMES,
    distance_word,
    operator_for_distance,
    signature_kind,
)
from .viewer.state import DEFAULT_THRESHOLD_SHARE, SHELL_COLORINGS

COMMANDS = ("compute", "render", "distance", "figures", "batch", "similar")
OPERATORS = OPERATOR_NAMES
KINDS = {kind: operator_for_distance(kind) for kind in DISTANCE_KINDS}


PREVIEW_REMOVED = (
    "--preview was removed: every spectrum is exact. For the lowest modes sooner ask for "
    "fewer modes (-k); from Python, compute_spectrum(..., on_modes=callback) hands over "
    "the lowest exact modes as they converge"
)
"""What any command says to ``--preview`` (an argument error, exit code 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit code 2
        if message.startswith("unrecognized arguments:"):
            given = message.split(":", 1)[1].split()
            if any(a == "--preview" or a.startswith("--preview=") for a in given):
                message = PREVIEW_REMOVED
        sys.stderr.write(f"modalviewer: error: {message}\n")
        raise SystemExit(2)


def _counting_modes(progress, k: int):
    """``(progress, on_modes)`` for :func:`modalviewer.compute_spectrum`: the progress
    says how many modes have converged ("solving: 12 of 100 modes ready")."""
    ready = [0]

    def on_modes(spec) -> None:
        ready[0] = spec.k

    def counted(stage: str, fraction: float) -> None:
        if stage == "solving" and ready[0]:
            stage = f"solving: {ready[0]} of {k} modes ready"
        progress(stage, fraction)

    return counted, on_modes


_BAR = {"open": False}  # a progress bar line is not finished: an error starts a new one


def _progress_bar():
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
        _BAR["open"] = fraction < 1.0
        if fraction >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return progress


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must look like 1024x768, got {text!r}") from None
    if not (16 <= w <= 8192 and 16 <= h <= 8192):
        raise argparse.ArgumentTypeError("width and height must be between 16 and 8192")
    return w, h


def _mode_list(text: str) -> list[int]:
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


def _grid(text: str) -> tuple[int, int]:
    try:
        columns, rows = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"a grid looks like 4x2, got {text!r}") from None
    if columns < 1 or rows < 1:
        raise argparse.ArgumentTypeError("a grid has at least one column and one row")
    return columns, rows


def _whole(least: int):
    """An argparse type: an integer of at least ``least`` (a one-line error naming the
    argument, exit code 2)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"a whole number is needed, got {text!r}") from None
        if value < least:
            raise argparse.ArgumentTypeError(f"must be at least {least}, got {value}")
        return value

    return parse


def _number(low: float = 0.0, low_included: bool = True, high: float = np.inf):
    """An argparse type: a finite number in [low, high] (low excluded unless
    ``low_included``); a one-line error naming the argument, exit code 2."""

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


COUNT = _whole(1)
MODE_INDEX = _whole(0)
WEIGHT = _number()


def _view(text: str):
    from .viewer.camera import parse_view

    try:
        return parse_view(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _camera_arguments(parser) -> None:
    from .viewer.camera import UP_CHOICES

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


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="modalviewer", description="Headless modal shape analysis.")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    c = sub.add_parser("compute", help="compute a spectrum and save it as .npz")
    c.add_argument("mesh")
    c.add_argument("--operator", choices=OPERATORS, default="laplacian")
    c.add_argument(
        "-k", type=COUNT, default=DEFAULT_K, help=f"number of modes (default: {DEFAULT_K})"
    )
    c.add_argument("--bending", type=WEIGHT, default=1.0)
    c.add_argument("--membrane", type=WEIGHT, default=1.0)
    c.add_argument("-o", "--output", required=True)
    c.add_argument(
        "--fix-slivers",
        action="store_true",
        help="first remove needle and cap triangles with modalviewer.fix_slivers (needs "
        "the optional pymeshlab: pip install 'modalviewer[repair]')",
    )
    _partial_argument(c)
    r = sub.add_parser("render", help="render a mode to PNG")
    r.add_argument("mesh")
    r.add_argument("--operator", choices=OPERATORS, default="laplacian")
    which = r.add_mutually_exclusive_group(required=True)
    which.add_argument("--mode", type=MODE_INDEX)
    which.add_argument(
        "--modes",
        type=_mode_list,
        help="several modes side by side in one picture, e.g. 1-8 or 2,5,9 (one camera, "
        "one colour bar)",
    )
    r.add_argument(
        "--grid",
        type=_grid,
        default=None,
        help="with --modes: COLUMNSxROWS of the panels (default: rows of up to 4)",
    )
    r.add_argument(
        "-k", type=COUNT, default=None, help=f"number of modes (default: the viewer's, {DEFAULT_K})"
    )
    r.add_argument("--isolines", type=_whole(0), default=12)
    r.add_argument(
        "--show",
        choices=SHELL_COLORINGS,
        default="deformed",
        help="3D vibration modes (shells): the deformed shape over the rest shape's ghost "
        "(default), or the normal component or the magnitude on the rest shape",
    )
    r.add_argument(
        "--size",
        type=_size,
        default=None,
        help="WIDTHxHEIGHT in pixels (default 1024x768; 640x480 with --animate)",
    )
    r.add_argument("--transparent", action="store_true")
    r.add_argument(
        "--animate",
        action="store_true",
        help="write one period of the mode vibrating as the window shows it: -o NAME.gif "
        "(or NAME.mp4 where imageio-ffmpeg is installed: pip install 'modalviewer[video]')",
    )
    r.add_argument(
        "--frames",
        type=_whole(2),
        default=None,
        help="with --animate: frames in the period (default: one period at the window's "
        "speed, 52 at 25 fps)",
    )
    r.add_argument(
        "--fps", type=_whole(1), default=25, help="with --animate: frames per second (default 25)"
    )
    r.add_argument(
        "--marker",
        action="store_true",
        help="draw the picked vertex's marker (mode pictures leave it out)",
    )
    _camera_arguments(r)
    r.add_argument("-o", "--output", required=True)
    r.add_argument(
        "--fix-slivers",
        action="store_true",
        help="first remove needle and cap triangles with modalviewer.fix_slivers (needs "
        "the optional pymeshlab: pip install 'modalviewer[repair]')",
    )
    _partial_argument(r)
    d = sub.add_parser(
        "distance", help="distance from a vertex to all vertices (of a second mesh with --to)"
    )
    d.add_argument("mesh")
    d.add_argument(
        "--vertex",
        type=_whole(0),
        required=True,
        help="the vertex's number in the file (0-based, counting every vertex of the file, "
        "also ones no face uses), as the viewer shows it",
    )
    d.add_argument(
        "--kind",
        choices=tuple(KINDS),
        default="vibration",
        help="vibration (3D shells), feature (E_D^N), hks (heat kernel of the Laplacian) or "
        "wks (wave kernel signature of the Laplacian, over energies)",
    )
    d.add_argument(
        "-k", type=COUNT, default=DEFAULT_K, help=f"number of modes (default: {DEFAULT_K})"
    )
    marked = d.add_mutually_exclusive_group()
    marked.add_argument(
        "--share",
        type=_number(0.0, False, 1.0),
        nargs="?",
        const=DEFAULT_THRESHOLD_SHARE,
        default=None,
        metavar="F",
        help="threshold map marking this share (0..1] of the surface's area similar, as the "
        f"viewer's threshold display (--share alone: {DEFAULT_THRESHOLD_SHARE:g}, the "
        "viewer's first threshold); with --to, of B's area",
    )
    marked.add_argument(
        "--threshold",
        type=_number(0.0, False),
        default=None,
        metavar="D",
        help="threshold map at this absolute distance (marks where distance <= D)",
    )
    d.add_argument("--size", type=_size, default=(1024, 768))
    d.add_argument("-o", "--output", default=None, help="PNG of the distance map")
    _camera_arguments(d)
    d.add_argument(
        "--csv",
        default=None,
        help="write vertex,distance rows: one per vertex of the file, numbered as in the "
        "file, the distance empty where no face uses the vertex",
    )
    d.add_argument(
        "--to",
        default=None,
        metavar="MESH_B",
        help="distance to every vertex of this second mesh instead (vertex of MESH_B, distance)",
    )
    d.add_argument(
        "--rescale",
        action="store_true",
        help="with --to: scale both meshes to unit area before computing",
    )
    d.add_argument(
        "--fix-slivers",
        action="store_true",
        help="first remove needle and cap triangles with modalviewer.fix_slivers (needs "
        "the optional pymeshlab: pip install 'modalviewer[repair]'); with --to, both meshes",
    )
    _partial_argument(d)
    f = sub.add_parser("figures", help="rebuild the paper's figures on the demo meshes")
    f.add_argument("-o", "--output", default="screenshots")
    from .batch_cli import add_parsers

    add_parsers(sub)  # batch, similar
    return p


def _viewer(mesh, path):
    """A :class:`~modalviewer.viewer.Viewer` showing ``mesh`` (no window, no Qt: its
    pictures are drawn off screen by the same scene the window draws)."""
    from .viewer import Viewer

    viewer = Viewer()
    viewer.set_mesh(mesh, Path(path))
    return viewer


def _run(args) -> int:
    import modalviewer as mv

    if args.command == "render" and args.modes is not None and args.animate:
        raise _BadArgument("--animate shows one mode: give --mode")
    if args.command == "render" and args.grid is not None:
        if args.modes is None:
            raise _BadArgument("--grid applies to several modes (--modes)")
        if args.grid[0] * args.grid[1] < len(args.modes):
            raise _BadArgument(
                f"--grid {args.grid[0]}x{args.grid[1]} has fewer cells than the "
                f"{len(args.modes)} modes"
            )
    if args.command == "render" and args.animate:  # before any work
        from .scene.animation import animation_path, check_size

        try:
            check_size(args.output, args.size or (2, 2))
            animation_path(args.output)
        except ValueError as exc:
            raise _BadArgument(f"-o {args.output}: {exc}") from None
    elif args.command == "render" and args.frames is not None:
        raise _BadArgument("--frames applies to an animation (--animate)")
    elif args.command in ("render", "distance") and args.output:
        from .scene.export import OTHER_PICTURE_SUFFIXES

        if Path(args.output).suffix.lower() in OTHER_PICTURE_SUFFIXES:  # before any work
            raise _BadArgument(
                f"-o {args.output}: pictures are written as PNG; give a name ending in .png"
            )

    for option, path in _outputs(args):  # before any work: a folder that cannot be made
        _make_folder(option, Path(path))

    if args.command in ("batch", "similar"):
        from .batch_cli import run

        return run(args)
    if args.command == "figures":
        from .figures import build_figures

        made = build_figures(args.output)  # prints a "wrote" line per figure
        print(f"{len(made)} figures written to {args.output}")
        return 0
    if args.command == "compute":
        from .processes.memory import prepare_compute_process

        prepare_compute_process()  # this process exists to compute (see processes.memory)
        mesh = _load(args.mesh, args.fix_slivers, args.partial)
        _refuse_if_too_large(mesh, args.operator, args.k)
        bar, on_modes = _counting_modes(_progress_bar(), args.k)
        with _warnings_printed():
            spec = mv.compute_spectrum(
                mesh,
                args.operator,
                args.k,
                args.bending,
                args.membrane,
                progress=bar,
                on_modes=on_modes,
            )
        mv.save_spectrum(spec, args.output)
        _wrote(args.output, f"spectrum, {spec.k} {args.operator} modes")
        from .viewer.model import memory_text, residual_text

        if spec.k < args.k:
            from .core.operators import operator_info

            unknowns = operator_info(args.operator).unknowns(mesh.n_vertices)
            whole = f": all the mesh has ({unknowns} unknowns)" if spec.k >= unknowns else ""
            print(f"asked for {args.k} modes, {spec.k} came{whole}")
        print(
            f"{Path(args.mesh).name}: {spec.k} {args.operator} modes, eigenvalues "
            f"{spec.eigenvalues[0]:.6g} .. {spec.eigenvalues[-1]:.6g}, "
            f"{residual_text(spec)}{memory_text(spec)}"
        )
        if spec.parameters.get("null_space"):
            print(f"null space: {spec.parameters['null_space']}")
        stages = spec.parameters.get("seconds_by_stage", {})
        if stages:
            busiest = sorted(stages.items(), key=lambda item: -item[1])[:4]
            print(
                f"{spec.parameters['seconds_total']:.1f} s in all; solver: "
                + ", ".join(f"{name} {seconds:.1f} s" for name, seconds in busiest)
                + f" ({spec.parameters['operator_columns']} operator columns)"
            )
        return 0
    mesh = _load(args.mesh, args.fix_slivers, args.partial)
    if args.command == "render":
        from .scene.grid import grid_shape, padded, panel_size

        viewer = _viewer(mesh, args.mesh)
        viewer.state.set_isolines(args.isolines)
        viewer.state.set_shell_coloring(args.show)
        with _warnings_printed():
            spec = viewer.compute(args.operator, k=args.k, wait=True)
        asked = [args.mode] if args.modes is None else args.modes
        if not all(0 <= j < spec.k for j in asked):
            option = "--mode" if args.modes is None else "--modes"
            raise _BadArgument(f"{option} must be between 0 and {spec.k - 1}")
        viewer.show_mode(asked[0])
        viewer.set_view(args.view, up=args.up)
        if args.modes is not None:
            from .scene.export import png_path, save_png

            size = args.size or (1024, 768)
            grid = args.grid or grid_shape(len(args.modes))
            try:
                panel = panel_size(size, len(args.modes), grid)
            except ValueError as exc:
                raise _BadArgument(f"--size {size[0]}x{size[1]}: {exc}") from None
            img = viewer.mode_grid(args.modes, grid=grid, size=panel)
            written = save_png(png_path(args.output), padded(img, size))
            viewer.close()
            shown = ", ".join(f"{j}: {spec.eigenvalues[j]:.6g}" for j in args.modes)
            print(f"modes of {args.operator}: lambda {shown}")
            _wrote(written, f"{_png(written)}, {len(args.modes)} modes")
            return 0
        if args.animate:
            written = viewer.export_animation(
                args.output, frames=args.frames, fps=args.fps, size=args.size, marker=args.marker
            )
        else:
            written = viewer.export_screenshot(
                args.output, transparent=args.transparent, size=args.size, marker=args.marker
            )
        viewer.close()
        print(f"mode {args.mode} of {args.operator}: lambda = {spec.eigenvalues[args.mode]:.6g}")
        _wrote(written, f"{_picture(written)}, mode {args.mode}")
        return 0
    # distance: computed on the vertices faces use (mesh.solver_mesh, whose map gives the
    # input's numbers); --vertex and every vertex number printed or written are the file's
    mesh = mesh.solver_mesh
    vertex = _mesh_vertex(mesh, args.vertex)
    if args.to is not None:
        return _distance_to(args, mesh)
    if args.rescale:
        raise ValueError("--rescale applies to two meshes (with --to)")
    spec = _cached_spectrum(mesh, KINDS[args.kind], args.k)
    d = mv.multiscale_distance(spec, vertex, kind=signature_kind(args.kind))
    marked = _threshold(args, mesh, d)
    if args.csv:
        _write_csv(args.csv, mesh, d, f"{args.kind} distance from vertex {args.vertex}")
    if args.output:
        viewer = _viewer(mesh, args.mesh)
        viewer.add_spectrum(spec)
        viewer.state.set_display(distance_kind=args.kind)
        viewer.pick_vertex(args.vertex)
        if marked is None:
            viewer.show_distance(args.kind, display="continuous")
        else:
            viewer.show_distance(args.kind, display="threshold", threshold=marked[0])
        viewer.set_view(args.view, up=args.up)
        written = viewer.export_screenshot(args.output, size=args.size)
        viewer.close()
        _wrote(written, f"{_png(written)}, {args.kind} distance map")
    order = np.argsort(d)[1:6]
    print(
        f"{args.kind} distance from vertex {args.vertex}: max {d.max():.6g}; nearest "
        + ", ".join(f"{mesh.file_vertex(i)} ({d[i]:.3g})" for i in order)
    )
    if marked is not None:
        print(
            f"threshold {marked[0]:.6g} ({marked[0] / d.max():.3g} of the largest distance): "
            f"{100 * marked[1]:.2f} % of the surface's area is at most that far"
        )
    return 0


def _threshold(args, mesh, d: np.ndarray) -> tuple[float, float] | None:
    """(distance, share of ``mesh``'s area where ``d`` is at most it) of ``--share`` or
    ``--threshold``, or None without either: the share turned into a distance as the
    viewer's threshold display does (by area, ``DerivedValues.threshold_for_share``)."""
    if args.share is None and args.threshold is None:
        return None
    from .viewer.state import ViewerState

    state = ViewerState()
    state.set_mesh(mesh)
    if args.threshold is not None:
        value = float(args.threshold)
    else:
        value = state.derived.threshold_for_share(args.share, d) * float(d.max())
    return value, state.derived.surface_share(d, value)


def _refuse_if_too_large(mesh, operator: str, k: int) -> None:
    """The viewer's memory check before an exact computation starts: a ValueError saying
    what would fit where it would need more than its share of this machine's memory."""
    from .viewer.model import memory_refusal
    from .viewer.state import ComputeSettings

    refusal = memory_refusal(
        ComputeSettings().key(operator, k),
        mesh.n_vertices,
        coarse="on a decimated copy",
    )
    if refusal:
        raise ValueError(refusal)


def _outputs(args) -> list[tuple[str, str]]:
    """(option, path) of the files a headless command writes (not batch's store)."""
    if args.command not in ("compute", "render", "distance"):
        return []
    found = [("-o", args.output)] if getattr(args, "output", None) else []
    if getattr(args, "csv", None):
        found.append(("--csv", args.csv))
    return found


def _make_folder(option: str, path: Path) -> None:
    """Create ``path``'s folder (and its parents) as pictures' exports do
    (:func:`.core.files.make_folder_for`), before any work; an argument error (exit code
    2) where it cannot be made or written in."""
    from .core.files import make_folder_for

    try:
        make_folder_for(path)
    except OSError as exc:
        raise _BadArgument(f"{option} {path}: {exc}") from None


class _Unavailable(Exception):
    """An option needing an optional package that is not installed (exit code 2)."""


class _BadArgument(ValueError):
    """An argument out of range that only the computation's result shows (``--mode``
    beyond the modes computed): exit code 2, as argparse's own errors."""


def _partial_argument(parser) -> None:
    parser.add_argument(
        "--partial",
        action="store_true",
        help="read a damaged or truncated file's whole records and say what was dropped "
        "(without it such a file is refused, naming the place of the damage)",
    )


def _load(path, fix_slivers: bool = False, partial: bool = False):
    """The mesh read from ``path``; with ``fix_slivers``, repaired by
    :func:`modalviewer.fix_slivers`, whose report is printed.  A damaged or truncated
    file is refused with the place of the damage and the advice of ``--partial``, which
    reads its whole records and prints what was dropped.  The load's report is printed
    where it says more than the mesh's shape."""
    import modalviewer as mv

    from .core.mesh import MeshError
    from .readers import DamagedFileError

    if fix_slivers:  # before reading: a missing package is found out at once
        from .repair import REPAIR_PACKAGES

        module, command = REPAIR_PACKAGES["fix_slivers"]
        try:
            __import__(module)
        except ImportError:
            raise _Unavailable(
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
        mesh = mv.fix_slivers(mesh, progress=_progress_bar())
        print(f"{Path(path).name}: fix slivers: {' '.join(mesh.report.messages)}")
    return mesh


def _png(path) -> str:
    """The image written, as "PNG WxH" (a window has a smallest size)."""
    from PIL import Image

    with Image.open(path) as image:
        return f"PNG {image.width}x{image.height}"


def _picture(path) -> str:
    """The picture or animation written: "PNG WxH", "GIF WxH, N frames" or "MP4"."""
    if Path(path).suffix.lower() == ".mp4":
        return "MP4"
    if Path(path).suffix.lower() == ".gif":
        from PIL import Image

        with Image.open(path) as image:
            return f"GIF {image.width}x{image.height}, {image.n_frames} frames"
    return _png(path)


def _wrote(path, what: str) -> None:
    """The line every command prints per file it wrote."""
    print(f"wrote {path} ({what})")


class _warnings_printed:
    """Warnings of the core raised inside the block (mv.ZeroModesWarning, ...) printed as
    one ``modalviewer: warning:`` line each on stderr, no source line."""

    def __enter__(self):
        import warnings

        self._catch = warnings.catch_warnings(record=True)
        self.caught = self._catch.__enter__()
        warnings.simplefilter("always")
        return self

    def __exit__(self, *exc):
        self._catch.__exit__(*exc)
        for warning in self.caught:
            sys.stderr.write(f"modalviewer: warning: {warning.message}\n")
        return False


def _mesh_vertex(mesh, number: int) -> int:
    """The mesh vertex of ``--vertex number`` (the file's numbering)."""
    from .core.mesh import MeshError

    try:
        return mesh.mesh_vertex(number)
    except MeshError as exc:
        raise _BadArgument(f"--vertex {number}: {exc}") from None


def _write_csv(path, mesh, d: np.ndarray, what: str) -> None:
    """Rows ``vertex,distance``, one per vertex of ``mesh``'s file in the file's numbering;
    the distance is empty at a file vertex no face uses (merged duplicates share theirs)."""
    values = mesh.to_file_field(d)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("vertex,distance\n")
        for i, x in enumerate(values.tolist()):
            fh.write(f"{i},{x:.10g}\n" if x == x else f"{i},\n")
    unused = int(np.isnan(values).sum())
    note = f", {unused} empty (vertices no face uses)" if unused else ""
    _wrote(path, f"CSV, {len(values)} rows vertex,distance{note}: {what}")


def _cached_spectrum(mesh, operator: str, k: int):
    """The spectrum from the viewer's disk cache (``$MODALVIEWER_CACHE``), or computed
    with a progress bar and cached, so a second pick on the same meshes is quick."""
    from .spectra import cached_or_computed

    with _warnings_printed():
        return cached_or_computed(mesh, operator, k, progress=_progress_bar())


def _distance_to(args, mesh_a) -> int:
    """``distance A --vertex V --to B``: from vertex V of A to every vertex of B."""
    import warnings

    import modalviewer as mv

    if args.up != "auto" or args.view != "canonical":
        # each panel of the two-mesh picture turns to face its marker
        raise ValueError(
            "--up and --view apply to one mesh's picture; with --to each mesh is shown "
            "from its first view, turned to face the picked vertex and its best match"
        )
    mesh_b = _load(args.to, args.fix_slivers, args.partial)
    mesh_b = mesh_b.solver_mesh  # as mesh_a: the vertices faces use, with the file's numbers
    if args.rescale:
        mesh_a, mesh_b = mv.rescale_to_area(mesh_a), mv.rescale_to_area(mesh_b)
    operator = KINDS[args.kind]
    spec_a = _cached_spectrum(mesh_a, operator, args.k)
    spec_b = _cached_spectrum(mesh_b, operator, args.k)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", mv.ScaleWarning)
        try:
            tables = mv.CrossTables(spec_a, spec_b, kind=signature_kind(args.kind))
        except ValueError as exc:  # the library's advice, in this command's options
            if args.rescale or "do not overlap" not in str(exc):
                raise
            raise ValueError(
                str(exc).replace(" (rescale both to the same area) or pass t_range", "")
                + "; --rescale rescales both to the same area"
            ) from None
    for warning in caught:
        sys.stderr.write(f"modalviewer: warning: {warning.message} (or pass --rescale)\n")
    vertex = _mesh_vertex(mesh_a, args.vertex)  # the file's numbers in, and out below
    d = tables.a_to_b(vertex)
    best_mesh = int(np.argmin(d))
    back_mesh = int(np.argmin(tables.b_to_a(best_mesh)))
    best, back = mesh_b.file_vertex(best_mesh), mesh_a.file_vertex(back_mesh)
    marked = _threshold(args, mesh_b, d)
    if args.csv:
        _write_csv(
            args.csv,
            mesh_b,
            d,
            f"{args.kind} distance from vertex {args.vertex} of A to B's vertices",
        )
    if args.output:
        from .cross_figure import Panel, render_panels

        label = distance_word(args.kind)
        display = "continuous" if marked is None else "threshold"
        panels = [
            Panel(
                mesh_a,
                f"{Path(args.mesh).name}: vertex {args.vertex}",
                vertex,
                face_marker=True,
            ),
            Panel(
                mesh_b,
                f"{Path(args.to).name}: {label} distance, best match {best}",
                marker=best_mesh,
                distances=d,
                display=display,
                threshold=1.0 if marked is None else min(1.0, marked[0] / float(d.max())),
                face_marker=True,
                colorbar=f"{label} distance",
            ),
        ]
        render_panels(panels, args.output, (max(16, args.size[0] // 2), args.size[1]))
        _wrote(
            args.output,
            f"{_png(args.output)}, vertex {args.vertex} of A, {args.kind} distance on B",
        )
    order = np.argsort(d, kind="stable")[:5]
    print(
        f"{args.kind} distance from vertex {args.vertex} of {Path(args.mesh).name} to "
        f"{Path(args.to).name} (scales {tables.times[0]:.4g} .. {tables.times[-1]:.4g}): "
        f"max {d.max():.6g}; best match {best} ({d[best_mesh]:.3g}), "
        + ("mutual" if back_mesh == vertex else f"not mutual (its best match on A is {back})")
        + "; nearest "
        + ", ".join(f"{mesh_b.file_vertex(i)} ({d[i]:.3g})" for i in order)
    )
    if marked is not None:
        # between two meshes even the best match is at a distance above zero
        print(
            f"threshold {marked[0]:.6g} ({marked[0] / d.max():.3g} of the largest distance): "
            f"{100 * marked[1]:.2f} % of {Path(args.to).name}'s area is at most that far (the "
            f"best match is at {d[best_mesh] / d.max():.3g} of the largest)"
        )
    return 0


_DASH_VALUES = ("--view", "--up")
"""Options whose values may start with "-" (``--view -x``, ``--view -30,10``, ``--up
-z``): argparse reads such a value as an option unless it is joined with "="."""


def _joined_dash_values(argv: list[str]) -> list[str]:
    """``argv`` with ``--view -x`` written ``--view=-x`` (see :data:`_DASH_VALUES`)."""
    out: list[str] = []
    i = 0
    while i < len(argv):
        value = argv[i + 1] if i + 1 < len(argv) else ""
        if argv[i] in _DASH_VALUES and value.startswith("-") and not value.startswith("--"):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
            continue
        out.append(argv[i])
        i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(_joined_dash_values(argv))
    from .core.eigen import Cancelled

    try:
        return _run(args)
    except KeyboardInterrupt:
        sys.stderr.write("modalviewer: interrupted\n")
        return 130
    except Cancelled:
        return 130
    except (_Unavailable, _BadArgument) as exc:
        if _BAR["open"]:
            sys.stderr.write("\n")
        sys.stderr.write(f"modalviewer: error: {exc}\n")
        return 2
    except (ValueError, OSError, RuntimeError, MemoryError) as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        from .repair import repair_for_failure

        if _BAR["open"]:
            sys.stderr.write("\n")
        if repair_for_failure(message) == "fix_slivers" and not getattr(args, "fix_slivers", False):
            message += "; retry with --fix-slivers"
        sys.stderr.write(f"modalviewer: error: {message}\n")
        return 1
