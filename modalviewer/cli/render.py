"""``modalviewer render`` (a mode, several side by side, or a mode vibrating) and
``modalviewer figures``."""

from __future__ import annotations

from ..core.operators import DEFAULT_K, OPERATOR_NAMES
from ..viewer.state import SHELL_COLORINGS
from .common import (
    COUNT,
    MODE_INDEX,
    BadArgument,
    add_camera_arguments,
    add_mesh_arguments,
    load,
    make_output_folders,
    mode_list,
    picture_text,
    refuse_other_picture_suffix,
    size,
    two_numbers,
    viewer_of,
    warnings_printed,
    whole,
    wrote,
)


def add_parsers(sub) -> None:
    r = sub.add_parser("render", help="render a mode to PNG")
    r.add_argument("mesh")
    r.add_argument("--operator", choices=OPERATOR_NAMES, default="laplacian")
    which = r.add_mutually_exclusive_group(required=True)
    which.add_argument("--mode", type=MODE_INDEX)
    which.add_argument(
        "--modes",
        type=mode_list,
        help="several modes side by side in one picture, e.g. 1-8 or 2,5,9 (one camera, "
        "one colour bar)",
    )
    r.add_argument(
        "--grid",
        type=two_numbers("a grid", "4x2", 1),
        help="with --modes: COLUMNSxROWS of the panels (default: rows of up to 4)",
    )
    r.add_argument("-k", type=COUNT, help=f"number of modes (default: the viewer's, {DEFAULT_K})")
    r.add_argument("--isolines", type=whole(0), default=12)
    r.add_argument(
        "--show",
        choices=SHELL_COLORINGS,
        default="deformed",
        help="3D vibration modes (shells): the deformed shape over the rest shape's ghost "
        "(default), or the normal component or the magnitude on the rest shape",
    )
    r.add_argument(
        "--size",
        type=size,
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
        type=whole(2),
        help="with --animate: frames in the period (default: one period at the window's "
        "speed, 52 at 25 fps)",
    )
    r.add_argument(
        "--fps", type=whole(1), default=25, help="with --animate: frames per second (default 25)"
    )
    r.add_argument(
        "--marker",
        action="store_true",
        help="draw the picked vertex's marker (mode pictures leave it out)",
    )
    add_camera_arguments(r)
    r.add_argument("-o", "--output", required=True)
    add_mesh_arguments(r)
    r.set_defaults(func=render)


def add_figures_parser(sub) -> None:
    f = sub.add_parser("figures", help="rebuild the paper's figures on the demo meshes")
    f.add_argument("-o", "--output", default="screenshots")
    f.set_defaults(func=figures)


def _check(args) -> None:
    """The argument errors found before any work."""
    if args.modes is not None and args.animate:
        raise BadArgument("--animate shows one mode: give --mode")
    if args.grid is not None:
        if args.modes is None:
            raise BadArgument("--grid applies to several modes (--modes)")
        if args.grid[0] * args.grid[1] < len(args.modes):
            raise BadArgument(
                f"--grid {args.grid[0]}x{args.grid[1]} has fewer cells than the "
                f"{len(args.modes)} modes"
            )
    if args.animate:
        from ..scene.animation import animation_path

        try:
            animation_path(args.output, args.size)
        except ValueError as exc:
            raise BadArgument(f"-o {args.output}: {exc}") from None
    elif args.frames is not None:
        raise BadArgument("--frames applies to an animation (--animate)")
    else:
        refuse_other_picture_suffix(args.output)
    make_output_folders(("-o", args.output))


def render(args) -> int:
    from ..scene.grid import grid_shape, padded, panel_size

    _check(args)
    mesh = load(args.mesh, args.fix_slivers, args.partial)
    viewer = viewer_of(mesh, args.mesh)
    viewer.state.style.isolines = args.isolines
    viewer.state.style.shell_coloring = args.show
    with warnings_printed():
        spec = viewer.compute(args.operator, k=args.k, wait=True)
    asked = [args.mode] if args.modes is None else args.modes
    if not all(0 <= j < spec.k for j in asked):
        option = "--mode" if args.modes is None else "--modes"
        raise BadArgument(f"{option} must be between 0 and {spec.k - 1}")
    viewer.show_mode(asked[0])
    viewer.set_view(args.view, up=args.up)
    if args.modes is not None:
        from ..scene.export import save_png

        shape = args.size or (1024, 768)
        grid = args.grid or grid_shape(len(args.modes))
        try:
            panel = panel_size(shape, len(args.modes), grid)
        except ValueError as exc:
            raise BadArgument(f"--size {shape[0]}x{shape[1]}: {exc}") from None
        img = viewer.mode_grid(args.modes, grid=grid, size=panel)
        written = save_png(args.output, padded(img, shape))
        viewer.close()
        shown = ", ".join(f"{j}: {spec.eigenvalues[j]:.6g}" for j in args.modes)
        print(f"modes of {args.operator}: lambda {shown}")
        wrote(written, f"{picture_text(written)}, {len(args.modes)} modes")
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
    wrote(written, f"{picture_text(written)}, mode {args.mode}")
    return 0


def figures(args) -> int:
    from ..figures import build_figures

    made = build_figures(args.output)  # prints a "wrote" line per figure
    print(f"{len(made)} figures written to {args.output}")
    return 0
