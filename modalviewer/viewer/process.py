"""Work in a child process, with progress relayed (JSON lines on stdout) and cancel at once.

Sparse factorisations hold the GIL, so a computation in a thread would stall the event
loop; a child keeps it free and is killed to cancel.  MeshLab run in a thread of a
process that later runs MKL's solver corrupts the heap (abort at exit:
"malloc_consolidate(): unaligned fastbin chunk"); a child cannot.
"""

from __future__ import annotations

import json
import os
import pickle
import queue
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

from ..core.eigen import Cancelled
from ..core.factor import remove_stale_factor_folders
from ..core.mesh import Mesh
from ..core.spectrum import GrowingSpectrum, load_spectrum


class ChildError(RuntimeError):
    """A failure a child reported in words: a message for the user, not a fault here."""


def _run_child(argv: list[str], progress, cancel, what: str, on_modes=None) -> None:
    """Run ``python -m ...argv``; relay its progress (and its ``{"modes": path}`` lines
    to ``on_modes(path)``); kill it on cancel; raise its error."""
    child = subprocess.Popen(
        [sys.executable, "-m", *argv],
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

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
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
            elif "modes" in message and on_modes is not None:
                on_modes(message["modes"])
            elif "error" in message:
                error = message["error"]
    finally:
        if child.poll() is None:
            child.kill()
        child.wait()
        reader.join(timeout=5.0)  # the pipe's end reached: it can be closed
        if not reader.is_alive():  # else a stray grandchild holds it: left to the thread
            child.stdout.close()
        # a killed (cancelled) solve cannot remove its out-of-core factor file: it is
        # the folder of a process that has ended now
        remove_stale_factor_folders()
    if error is not None:
        raise ChildError(error)
    if child.returncode != 0:
        raise RuntimeError(
            f"the {what} process stopped unexpectedly (exit code {child.returncode}); "
            "it may have run out of memory"
        )


def _temp_path(suffix: str) -> str:
    fd, path = tempfile.mkstemp(prefix="modalviewer-job-", suffix=suffix)
    os.close(fd)
    return path


def compute_in_process(
    mesh,
    operator,
    k,
    bending,
    membrane,
    out_path,
    progress,
    cancel,
    on_modes=None,
):
    """Run ``modalviewer.processes.job_main`` in a child; returns the Spectrum it wrote to
    ``out_path`` (its error raised).  ``on_modes`` as :func:`modalviewer.compute_spectrum`'s,
    relayed through files and called in this thread."""
    params = {
        "operator": operator,
        "k": int(k),
        "bending": bending,
        "membrane": membrane,
    }
    job_path = _temp_path(".npz")
    with tempfile.TemporaryDirectory(prefix="modalviewer-modes-") as folder:
        relay = None
        if on_modes is not None:
            params["modes_folder"] = folder
            relay = _ModesReceived(mesh.hash, operator, on_modes)
        try:
            np.savez(job_path, vertices=mesh.vertices, faces=mesh.faces, params=json.dumps(params))
            argv = ["modalviewer.processes.job_main", job_path, str(out_path)]
            _run_child(argv, progress, cancel, "computation", relay)
        finally:
            Path(job_path).unlink(missing_ok=True)
    progress("reading the result", 0.98)
    return load_spectrum(out_path, mesh_hash=mesh.hash)


class _ModesReceived:
    """Gathers the mode files a child relays and calls ``on_modes`` with all so far."""

    def __init__(self, mesh_hash: str, operator: str, on_modes) -> None:
        self.mesh_hash, self.operator, self.on_modes = mesh_hash, operator, on_modes
        self.modes: GrowingSpectrum | None = None

    def __call__(self, path: str) -> None:
        with np.load(path, allow_pickle=False) as part:
            parameters = json.loads(str(part["parameters"]))
            if self.modes is None:
                self.modes = GrowingSpectrum(int(parameters["modes_requested"]))
                self.mass = part["mass"]
            self.modes.append(part["eigenvalues"], part["modes"])
        Path(path).unlink(missing_ok=True)
        self.on_modes(self.modes.so_far(self.operator, self.mass, self.mesh_hash, parameters))


def repair_in_process(name: str, mesh: Mesh, progress, cancel) -> Mesh:
    """Repair ``name`` (:data:`modalviewer.repair.REPAIRS`) of ``mesh`` in a child."""
    job_path, out_path = _temp_path(".pickle"), _temp_path(".pickle")
    try:
        source = mesh.input_mesh  # repaired in the input's numbering
        with open(job_path, "wb") as fh:
            job = (name, np.asarray(source.vertices), np.asarray(source.faces), source.report)
            pickle.dump((*job, source.file_map, np.asarray(source.merged_into)), fh)
        _run_child(
            ["modalviewer.processes.repair_main", job_path, out_path], progress, cancel, "repair"
        )
        return pickle.loads(Path(out_path).read_bytes())  # written by our own child just now
    finally:
        Path(job_path).unlink(missing_ok=True)
        Path(out_path).unlink(missing_ok=True)
