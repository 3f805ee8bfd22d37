"""A mesh repair in a child process: ``python -m modalviewer.processes.repair_main IN OUT``.

IN is a pickle of (repair name, vertices, faces, report, file_map, merged_into) written by
:func:`modalviewer.viewer.process.repair_in_process`; OUT receives the repaired Mesh
(pickled).  Progress and errors go to stdout as JSON lines.
"""

from __future__ import annotations

import pickle
import sys

from .job_main import emit, reported


def main(argv: list[str] | None = None) -> int:
    job_path, out_path = sys.argv[1:] if argv is None else argv
    from ..core.mesh import Mesh
    from ..repair import apply_repair

    def work() -> None:
        with open(job_path, "rb") as fh:
            name, vertices, faces, report, file_map, merged_into = pickle.load(fh)
        mesh = Mesh(vertices, faces, report=report, file_map=file_map, merged_into=merged_into)
        repaired = apply_repair(
            name, mesh, progress=lambda stage, f: emit({"stage": stage, "fraction": f})
        )
        with open(out_path, "wb") as fh:
            pickle.dump(repaired, fh)

    return reported(work, "not enough memory for this repair")


if __name__ == "__main__":
    sys.exit(main())
