"""``modalviewer distance``: from a vertex to every vertex of the mesh, or of a second
mesh (``--to``)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ..core.files import atomic_write
from ..core.operators import (
    DEFAULT_K,
    DISTANCE_KINDS,
    distance_word,
    operator_for_distance,
    signature_kind,
)
from ..viewer.state import DEFAULT_THRESHOLD_SHARE
from .common import (
    COUNT,
    BadArgument,
    add_camera_arguments,
    add_mesh_arguments,
    load,
    make_output_folders,
    number,
    picture_text,
    progress_bar,
    refuse_other_picture_suffix,
    size,
    viewer_of,
    warnings_printed,
    whole,
    wrote,
)


def add_parsers(sub) -> None:
    d = sub.add_parser(
        "distance", help="distance from a vertex to all vertices (of a second mesh with --to)"
    )
    d.add_argument("mesh")
    d.add_argument(
        "--vertex",
        type=whole(0),
        required=True,
        help="the vertex's number in the file (0-based, counting every vertex of the file, "
        "also ones no face uses), as the viewer shows it",
    )
    d.add_argument(
        "--kind",
        choices=tuple(DISTANCE_KINDS),
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
        type=number(0.0, False, 1.0),
        nargs="?",
        const=DEFAULT_THRESHOLD_SHARE,
        metavar="F",
        help="threshold map marking this share (0..1] of the surface's area similar, as the "
        f"viewer's threshold display (--share alone: {DEFAULT_THRESHOLD_SHARE:g}, the "
        "viewer's first threshold); with --to, of B's area",
    )
    marked.add_argument(
        "--threshold",
        type=number(0.0, False),
        metavar="D",
        help="threshold map at this absolute distance (marks where distance <= D)",
    )
    d.add_argument("--size", type=size, default=(1024, 768))
    d.add_argument("-o", "--output", help="PNG of the distance map")
    add_camera_arguments(d)
    d.add_argument(
        "--csv",
        help="write vertex,distance rows: one per vertex of the file, numbered as in the "
        "file, the distance empty where no face uses the vertex",
    )
    d.add_argument(
        "--to",
        metavar="MESH_B",
        help="distance to every vertex of this second mesh instead (vertex of MESH_B, distance)",
    )
    d.add_argument(
        "--rescale",
        action="store_true",
        help="with --to: scale both meshes to unit area before computing",
    )
    add_mesh_arguments(d, "; with --to, both meshes")
    d.set_defaults(func=distance)


def distance(args) -> int:
    import modalviewer as mv

    refuse_other_picture_suffix(args.output)
    make_output_folders(("-o", args.output), ("--csv", args.csv))
    # computed on the vertices faces use (mesh.solver_mesh, whose map gives the input's
    # numbers); --vertex and every vertex number printed or written are the file's
    mesh = load(args.mesh, args.fix_slivers, args.partial).solver_mesh
    vertex = _mesh_vertex(mesh, args.vertex)
    if args.to is not None:
        return _distance_to(args, mesh, vertex)
    if args.rescale:
        raise ValueError("--rescale applies to two meshes (with --to)")
    spec = _cached_spectrum(mesh, operator_for_distance(args.kind), args.k)
    d = mv.multiscale_distance(spec, vertex, kind=signature_kind(args.kind))
    marked = _threshold(args, mesh, d)
    if args.csv:
        _write_csv(args, mesh, d)
    if args.output:
        viewer = viewer_of(mesh, args.mesh)
        viewer.add_spectrum(spec)
        viewer.state.set_display(distance_kind=args.kind)
        viewer.pick_vertex(args.vertex)
        display = "continuous" if marked is None else "threshold"
        viewer.show_distance(args.kind, display, threshold=None if marked is None else marked[0])
        viewer.set_view(args.view, up=args.up)
        written = viewer.export_screenshot(args.output, size=args.size)
        viewer.close()
        wrote(written, f"{picture_text(written)}, {args.kind} distance map")
    order = np.argsort(d)[1:6]
    print(
        f"{args.kind} distance from vertex {args.vertex}: max {d.max():.6g}; nearest "
        + ", ".join(f"{mesh.file_vertex(i)} ({d[i]:.3g})" for i in order)
    )
    if marked is not None:
        print(f"{_threshold_text(marked, d)} the surface's area is at most that far")
    return 0


def _threshold(args, mesh, d: np.ndarray) -> tuple[float, float] | None:
    """(distance, share of ``mesh``'s area where ``d`` is at most it) of ``--share`` or
    ``--threshold``, or None without either: the share turned into a distance as the
    viewer's threshold display does (by area, ``DerivedValues.threshold_for_share``)."""
    if args.share is None and args.threshold is None:
        return None
    from ..viewer.state import ViewerState

    state = ViewerState()
    state.set_mesh(mesh)
    if args.threshold is not None:
        value = float(args.threshold)
    else:
        value = state.derived.threshold_for_share(args.share, d) * float(d.max())
    return value, state.derived.surface_share(d, value)


def _threshold_text(marked: tuple[float, float], d: np.ndarray) -> str:
    value, share = marked
    fraction = value / d.max()
    return f"threshold {value:.6g} ({fraction:.3g} of the largest distance): {100 * share:.2f} % of"


def _mesh_vertex(mesh, number: int) -> int:
    """The mesh vertex of ``--vertex number`` (the file's numbering)."""
    from ..core.mesh import MeshError

    try:
        return mesh.mesh_vertex(number)
    except MeshError as exc:
        raise BadArgument(f"--vertex {number}: {exc}") from None


def _write_csv(args, mesh, d: np.ndarray, to: str = "") -> None:
    """``--csv``: rows ``vertex,distance``, one per vertex of ``mesh``'s file in the file's
    numbering; the distance is empty at a file vertex no face uses (merged duplicates
    share theirs).  Written beside the target and renamed, so a failed run leaves no
    partial file."""
    values = mesh.to_file_field(d)
    rows = (f"{i},{x:.10g}\n" if x == x else f"{i},\n" for i, x in enumerate(values.tolist()))
    atomic_write(
        Path(args.csv),
        lambda tmp: Path(tmp).write_text("vertex,distance\n" + "".join(rows), encoding="utf-8"),
    )
    unused = int(np.isnan(values).sum())
    note = f", {unused} empty (vertices no face uses)" if unused else ""
    what = f"{args.kind} distance from vertex {args.vertex}{to}"
    wrote(args.csv, f"CSV, {len(values)} rows vertex,distance{note}: {what}")


def _cached_spectrum(mesh, operator: str, k: int):
    """The spectrum from the viewer's disk cache (``$MODALVIEWER_CACHE``), or computed
    with a progress bar and cached, so a second pick on the same meshes is quick."""
    from ..spectra import cached_or_computed

    with warnings_printed():
        return cached_or_computed(mesh, operator, k, progress=progress_bar())


def _distance_to(args, mesh_a, vertex: int) -> int:
    """``distance A --vertex V --to B``: from vertex V of A to every vertex of B."""
    import warnings

    import modalviewer as mv

    if args.up != "auto" or args.view != "canonical":
        # each panel of the two-mesh picture turns to face its marker
        raise ValueError(
            "--up and --view apply to one mesh's picture; with --to each mesh is shown "
            "from its first view, turned to face the picked vertex and its best match"
        )
    # as mesh_a: the vertices faces use, with the file's numbers
    mesh_b = load(args.to, args.fix_slivers, args.partial).solver_mesh
    name_a, name_b = Path(args.mesh).name, Path(args.to).name
    if args.rescale:
        mesh_a, mesh_b = mv.rescale_to_area(mesh_a), mv.rescale_to_area(mesh_b)
    operator = operator_for_distance(args.kind)
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
    d = tables.a_to_b(vertex)  # vertex: mesh_a's number of --vertex (rescaling keeps them)
    best_mesh = int(np.argmin(d))
    back_mesh = int(np.argmin(tables.b_to_a(best_mesh)))
    best, back = mesh_b.file_vertex(best_mesh), mesh_a.file_vertex(back_mesh)
    marked = _threshold(args, mesh_b, d)
    if args.csv:
        _write_csv(args, mesh_b, d, " of A to B's vertices")
    if args.output:
        from ..cross_figure import Panel, render_panels

        label = distance_word(args.kind)
        display = "continuous" if marked is None else "threshold"
        panels = [
            Panel(mesh_a, f"{name_a}: vertex {args.vertex}", vertex, face_marker=True),
            Panel(
                mesh_b,
                f"{name_b}: {label} distance, best match {best}",
                marker=best_mesh,
                distances=d,
                display=display,
                threshold=1.0 if marked is None else min(1.0, marked[0] / float(d.max())),
                face_marker=True,
                colorbar=f"{label} distance",
            ),
        ]
        render_panels(panels, args.output, (max(16, args.size[0] // 2), args.size[1]))
        what = f"vertex {args.vertex} of A, {args.kind} distance on B"
        wrote(args.output, f"{picture_text(args.output)}, {what}")
    order = np.argsort(d, kind="stable")[:5]
    print(
        f"{args.kind} distance from vertex {args.vertex} of {name_a} to {name_b} (scales "
        f"{tables.times[0]:.4g} .. {tables.times[-1]:.4g}): "
        f"max {d.max():.6g}; best match {best} ({d[best_mesh]:.3g}), "
        + ("mutual" if back_mesh == vertex else f"not mutual (its best match on A is {back})")
        + "; nearest "
        + ", ".join(f"{mesh_b.file_vertex(i)} ({d[i]:.3g})" for i in order)
    )
    if marked is not None:
        # between two meshes even the best match is at a distance above zero
        print(
            f"{_threshold_text(marked, d)} {name_b}'s area is at most that far (the best "
            f"match is at {d[best_mesh] / d.max():.3g} of the largest)"
        )
    return 0
