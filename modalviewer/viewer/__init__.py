"""The viewer without a window: :class:`Viewer`, one object (a :class:`ViewerModel`: the
evented state, the job queue and the spectrum cache, with the scripting API and pictures)
that the windows, the command line and notebooks share; sessions.  No Qt and no VTK here:
pictures are drawn by ``modalviewer.scene``, windows in ``modalviewer.gui`` observe the
state."""

from .jobs import Job, JobQueue, ManualDispatcher, RepairJob, SpectrumJob
from .model import ComputeRefused, ViewerModel
from .state import ComputeSettings, Display, SpectrumKey, ViewerState
from .viewer import ComputeError, Viewer

__all__ = [
    "ComputeError",
    "ComputeRefused",
    "ComputeSettings",
    "Display",
    "Job",
    "JobQueue",
    "ManualDispatcher",
    "RepairJob",
    "SpectrumJob",
    "SpectrumKey",
    "ViewerModel",
    "ViewerState",
    "Viewer",
]
