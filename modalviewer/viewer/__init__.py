"""The viewer's state, jobs and sessions, without Qt or VTK (``gui`` observes them)."""

from .jobs import Job, JobQueue, ManualDispatcher
from .model import ComputeRefused, ViewerModel
from .state import ComputeSettings, Display, SpectrumKey, ViewerState

__all__ = [
    "ComputeRefused",
    "ComputeSettings",
    "Display",
    "Job",
    "JobQueue",
    "ManualDispatcher",
    "SpectrumKey",
    "ViewerModel",
    "ViewerState",
]
