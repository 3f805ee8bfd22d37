"""A spectrum computation in a child process, with progress relayed and cancel at once.

Sparse factorisations hold the GIL, so a big computation in a thread would stall the
viewer's event loop; a child process keeps it free and is killed to cancel.
"""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

from ..core.eigen import Cancelled
from ..core.spectrum import load_spectrum


def compute_in_process(mesh, operator, k, bending, membrane, out_path, progress, cancel):
    """Run ``modalviewer.core.job_main`` in a child Python; relay progress; kill on cancel.

    Returns the Spectrum read back from ``out_path``; the child's error message is
    raised as RuntimeError.
    """
    params = {"operator": operator, "k": int(k), "bending": bending, "membrane": membrane}
    fd, job_path = tempfile.mkstemp(prefix="modalviewer-job-", suffix=".npz")
    os.close(fd)
    np.savez(job_path, vertices=mesh.vertices, faces=mesh.faces, params=json.dumps(params))
    child = subprocess.Popen(
        [sys.executable, "-m", "modalviewer.core.job_main", job_path, str(out_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        text=True,
    )
    lines: queue.Queue = queue.Queue()

    def pump():
        for line in child.stdout:
            lines.put(line)
        lines.put(None)

    threading.Thread(target=pump, daemon=True).start()
    progress("starting", 0.0)
    error = None
    try:
        while True:
            if cancel():
                raise Cancelled()
            try:
                line = lines.get(timeout=0.05)
            except queue.Empty:
                continue
            if line is None:
                break
            try:
                message = json.loads(line)
            except json.JSONDecodeError:
                continue
            if "stage" in message:
                progress(message["stage"], message["fraction"])
            elif "error" in message:
                error = message["error"]
    finally:
        if child.poll() is None:
            child.kill()
        child.wait()
        Path(job_path).unlink(missing_ok=True)
    if error is not None:
        raise RuntimeError(error)
    if child.returncode != 0:
        raise RuntimeError(
            f"the computation process stopped unexpectedly (exit code {child.returncode}); "
            "it may have run out of memory"
        )
    return load_spectrum(out_path, mesh_hash=mesh.hash)
