"""Cache or compute: how the viewer, the shape pair and the command line get a spectrum,
so that they share the same cache entries."""

from __future__ import annotations

from .core.cache import SpectrumCache
from .core.mesh import Mesh
from .core.operators import operator_info
from .core.pipeline import compute_spectrum
from .core.spectrum import Spectrum

PROCESS_THRESHOLD = 20000
"""With ``child_process``, exact spectra of at least this many unknowns are computed in
a separate process (sparse factorisations hold the GIL; a process also cancels at once)."""


def cached_or_computed(
    mesh: Mesh,
    operator: str,
    k: int,
    bending: float = 1.0,
    membrane: float = 1.0,
    *,
    cache: SpectrumCache | None = None,
    progress=None,
    cancel=None,
    on_modes=None,
    coarse: bool = False,
    child_process: bool = False,
) -> Spectrum:
    """``operator``'s ``k`` lowest modes on ``mesh`` from ``cache`` (default the user's), or
    computed and stored there (by a child process with ``child_process`` from
    :data:`PROCESS_THRESHOLD` unknowns); ``coarse``: coarse-to-fine, never cached."""
    cache = cache if cache is not None else SpectrumCache()
    weights = bending, membrane
    if coarse:
        from .coarsen import coarse_to_fine_spectrum

        return coarse_to_fine_spectrum(mesh, operator, k, *weights, progress, cancel)
    spec = cache.get(mesh, operator, k, *weights)
    if spec is not None:
        return spec
    if child_process and operator_info(operator).unknowns(mesh.n_vertices) >= PROCESS_THRESHOLD:
        from .viewer.process import compute_in_process

        target = cache.writable_path(mesh, operator, k, *weights)
        return compute_in_process(mesh, operator, k, *weights, target, progress, cancel, on_modes)
    spec = compute_spectrum(mesh, operator, k, *weights, progress, cancel, on_modes=on_modes)
    cache.put(mesh, spec, k, *weights)
    return spec
