"""A spectrum computation in a child process (why: :mod:`modalviewer.viewer.process`).

``python -m modalviewer.processes.job_main JOB OUT``: JOB.npz holds ``vertices``,
``faces`` and a JSON ``params`` (operator, k, bending, membrane, and ``modes_folder``
where the modes are relayed as they converge).  Progress goes to stdout as JSON lines
``{"stage": ..., "fraction": ...}``, the result to OUT.npz (atomically), a failure to
stdout as ``{"error": ...}`` with exit code 1.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np


def emit(payload: dict) -> None:
    """One JSON line to the viewer on stdout (progress, a result or an error)."""
    sys.stdout.write(json.dumps(payload) + "\n")
    sys.stdout.flush()


def reported(work, short_of_memory: str) -> int:
    """Run ``work()``; a failure goes to the viewer as ``{"error": ...}`` and exit code 1."""
    try:
        work()
    except MemoryError:
        emit({"error": short_of_memory})
        return 1
    except Exception as exc:  # reported to the viewer as a message
        emit({"error": str(exc) or type(exc).__name__})
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    job_path, out_path = argv
    from ..core.memory import prepare_compute_process
    from ..core.mesh import Mesh
    from ..core.pipeline import compute_spectrum
    from ..core.spectrum import save_spectrum

    prepare_compute_process()  # this process exists to compute (see core.memory)

    def work() -> None:
        with np.load(job_path, allow_pickle=False) as job:
            vertices, faces = job["vertices"], job["faces"]
            params = json.loads(str(job["params"]))
        mesh = Mesh(vertices, faces)
        folder = params.get("modes_folder")
        spec = compute_spectrum(
            mesh,
            params["operator"],
            int(params["k"]),
            float(params["bending"]),
            float(params["membrane"]),
            progress=_report,
            on_modes=None if folder is None else _ModesRelay(Path(folder)),
        )
        emit({"stage": "writing the result", "fraction": 0.97})
        save_spectrum(spec, out_path)
        emit({"done": out_path})

    return reported(work, "not enough memory for this computation; try fewer modes")


class _ModesRelay:
    """Hands the modes that converged to the viewer: each step's new modes go to a file
    ``modes-<j>.npz`` in ``folder`` (written whole, then renamed), announced as a line
    ``{"modes": path}``; the finished spectrum is not relayed (it is the result)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.sent = 0

    def __call__(self, spec) -> None:
        if spec.is_complete:
            return
        part = slice(self.sent, spec.k)
        path = self.folder / f"modes-{spec.k}.npz"
        partial = path.with_suffix(".partial.npz")
        np.savez(
            partial,
            eigenvalues=spec.eigenvalues[part],
            modes=spec.modes[..., part],
            mass=spec.mass,
            parameters=json.dumps(spec.parameters),
        )
        os.replace(partial, path)
        self.sent = spec.k
        emit({"modes": str(path)})


def _report(stage: str, fraction: float) -> None:
    """Progress to the viewer, below 1: the spectrum is still written and read back after."""
    if stage == "done":
        return
    emit({"stage": stage, "fraction": min(float(fraction), 0.96)})


if __name__ == "__main__":
    sys.exit(main())
