"""The coarse copy of a 3D shells preview, made in a child process.

``python -m modalviewer.processes.copy_main``: reads an ``.npz`` from stdin holding
``vertices``, ``faces`` and ``target`` (vertices of the copy) and writes one to stdout
with the copy's ``vertices`` and ``faces`` and, for each vertex of the mesh, its nearest
point on the copy as ``triangles`` and ``barycentric``; exit code 1 and nothing written
where no usable copy comes out.  No files: a killed process leaves nothing behind.  The
decimation's own memory (MeshLab's and VTK's libraries and working arrays) so ends with
this process instead of staying in the computing one
(:func:`modalviewer.coarsen.preview_copy`).
"""

from __future__ import annotations

import io
import os
import signal
import sys

import numpy as np


def _die_with_parent() -> None:
    """Ask Linux to end this process when its parent ends (a cancelled computation is
    killed; its copy would otherwise run on)."""
    from ..core.memory import glibc

    prctl = getattr(glibc(), "prctl", None)
    if prctl is not None:
        prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG


def main() -> int:
    _die_with_parent()
    result = os.fdopen(os.dup(1), "wb")  # the result's stream
    os.dup2(2, 1)  # whatever the libraries print goes to stderr, not into the result
    from ..coarsen import decimate_and_locate

    with np.load(io.BytesIO(sys.stdin.buffer.read()), allow_pickle=False) as job:
        vertices, faces, target = job["vertices"], job["faces"], int(job["target"])
    made = decimate_and_locate(vertices, faces, target)
    if made is None:
        return 1
    coarse, triangles, barycentric = made
    out = io.BytesIO()
    np.savez(
        out,
        vertices=coarse.vertices,
        faces=coarse.faces,
        triangles=triangles,
        barycentric=barycentric,
    )
    with result:
        result.write(out.getbuffer())
    return 0


if __name__ == "__main__":
    sys.exit(main())
