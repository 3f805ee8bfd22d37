"""``modalviewer compute``: a spectrum saved as ``.npz``."""

from __future__ import annotations

from pathlib import Path

from ..core.operators import DEFAULT_K, OPERATOR_NAMES
from .common import (
    COUNT,
    WEIGHT,
    add_mesh_arguments,
    load,
    make_output_folders,
    progress_bar,
    warnings_printed,
    wrote,
)


def add_parsers(sub) -> None:
    c = sub.add_parser("compute", help="compute a spectrum and save it as .npz")
    c.add_argument("mesh")
    c.add_argument("--operator", choices=OPERATOR_NAMES, default="laplacian")
    c.add_argument(
        "-k", type=COUNT, default=DEFAULT_K, help=f"number of modes (default: {DEFAULT_K})"
    )
    c.add_argument("--bending", type=WEIGHT, default=1.0)
    c.add_argument("--membrane", type=WEIGHT, default=1.0)
    c.add_argument("-o", "--output", required=True)
    add_mesh_arguments(c)
    c.set_defaults(func=compute)


def compute(args) -> int:
    import modalviewer as mv

    from ..coarsen import COARSE_FRACTION
    from ..core.memory import memory_refusal, prepare_compute_process
    from ..core.operators import operator_info
    from ..viewer.wording import memory_text, residual_text

    make_output_folders(("-o", args.output))
    prepare_compute_process()  # this process exists to compute (see core.memory)
    mesh = load(args.mesh, args.fix_slivers, args.partial)
    n = mesh.n_vertices  # the viewer's memory check, before the computation starts
    refusal = memory_refusal(
        operator_info(args.operator), args.k, n, round(COARSE_FRACTION * n), "on a decimated copy"
    )
    if refusal:
        raise ValueError(refusal)
    bar, ready = progress_bar(), [0]  # the progress says "solving: 12 of 100 modes ready"

    def on_modes(spec) -> None:
        ready[0] = spec.k

    def progress(stage: str, fraction: float) -> None:
        counted = stage == "solving" and ready[0]
        bar(f"solving: {ready[0]} of {args.k} modes ready" if counted else stage, fraction)

    with warnings_printed():
        spec = mv.compute_spectrum(
            mesh,
            args.operator,
            args.k,
            args.bending,
            args.membrane,
            progress=progress,
            on_modes=on_modes,
        )
    mv.save_spectrum(spec, args.output)
    wrote(args.output, f"spectrum, {spec.k} {args.operator} modes")
    if spec.k < args.k:
        unknowns = spec.operator_info.unknowns(mesh.n_vertices)
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
