"""Shape collections: the spectra, signatures and global descriptors of a whole dataset.

:func:`run_batch` (:mod:`.runner`) computes one spectrum per mesh (and, if asked, its
signatures and descriptors) on a Dask cluster or one mesh after another in this process,
into a store (:mod:`.store`, its format); :func:`open_collection` reads it (numpy only);
:meth:`Collection.similar` ranks it by spectral distance to a shape.
"""

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
