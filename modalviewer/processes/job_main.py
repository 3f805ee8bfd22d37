"""A spectrum computation in a child process.

``python -m modalviewer.processes.job_main JOB OUT``: JOB.npz holds ``vertices``,
``faces`` and a JSON ``params`` (operator, k, bending, membrane).  Progress goes to
stdout as JSON lines ``{"stage": ..., "fraction": ...}``, the result to OUT.npz (written
atomically), a failure to stdout as ``{"error": ...}`` with exit code 1.  A separate
process keeps the viewer's event loop free (sparse factorisations hold the GIL) and is
terminated at once to cancel.
"""

from __future__ import annotations

import json
import sys

import numpy as np


def _emit(payload: dict) -> None:
    sys.stdout.write(json.dumps(payload) + "\n")
    sys.stdout.flush()


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    job_path, out_path = argv
    from ..core.mesh import Mesh
    from ..core.pipeline import compute_spectrum
    from ..core.spectrum import save_spectrum
    from .memory import prepare_compute_process

    prepare_compute_process()  # this process exists to compute (see processes.memory)
    try:
        with np.load(job_path, allow_pickle=False) as job:
            vertices, faces = job["vertices"], job["faces"]
            params = json.loads(str(job["params"]))
        mesh = Mesh(vertices, faces)
        spec = compute_spectrum(
            mesh,
            params["operator"],
            int(params["k"]),
            float(params["bending"]),
            float(params["membrane"]),
            progress=_report,
        )
        _emit({"stage": "writing the result", "fraction": 0.97})
        save_spectrum(spec, out_path)
    except MemoryError:
        _emit({"error": "not enough memory for this computation; try fewer modes"})
        return 1
    except Exception as exc:  # reported to the viewer as a message
        _emit({"error": str(exc) or type(exc).__name__})
        return 1
    _emit({"done": out_path})
    return 0


def _report(stage: str, fraction: float) -> None:
    """Progress to the viewer; the computation's own "done" is not the end of the job
    (the spectrum is still written, read back and prepared), so it stops below 1."""
    if stage == "done":
        return
    _emit({"stage": stage, "fraction": min(float(fraction), 0.96)})


if __name__ == "__main__":
    sys.exit(main())
