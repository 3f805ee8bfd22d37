"""Shape collections: the spectra, signatures and global descriptors of a whole dataset,
computed by :func:`run_batch` (:mod:`.runner`) into a store (:mod:`.store`) that
:func:`open_collection` reads with numpy alone."""

from .runner import BatchSummary, find_meshes, mesh_names, process_mesh, run_batch
from .store import (
    HISTOGRAM_EDGES,
    Collection,
    CollectionError,
    Neighbour,
    nearest_rows,
    open_collection,
    shape_dna_distance,
)

__all__ = [
    "BatchSummary",
    "Collection",
    "CollectionError",
    "HISTOGRAM_EDGES",
    "Neighbour",
    "find_meshes",
    "mesh_names",
    "nearest_rows",
    "open_collection",
    "process_mesh",
    "run_batch",
    "shape_dna_distance",
]
