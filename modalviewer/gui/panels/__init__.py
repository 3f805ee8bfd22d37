"""Dock panels: each observes the viewer state and sets it on input, nothing else."""

from .animation import AnimationPanel
from .compute import ComputePanel
from .distances import DistancesPanel
from .jobs import JobsPanel
from .modes import ModesPanel
from .status import StatusLine

__all__ = [
    "AnimationPanel",
    "ComputePanel",
    "DistancesPanel",
    "JobsPanel",
    "ModesPanel",
    "StatusLine",
]
