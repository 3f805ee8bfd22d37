"""The viewer without a window (no Qt, no VTK): :class:`Viewer` (:mod:`.viewer` says what
it is), its state, jobs and sessions."""

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
