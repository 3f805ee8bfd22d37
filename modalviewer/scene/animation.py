"""Animations of a vibration mode written to a file: GIF through Pillow, MP4 through
imageio and its ffmpeg plugin (the ``video`` extra), each written atomically; the
frames are drawn as the window draws them (:meth:`.view.StateScene.animation_frame`)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

from ..core.files import atomic_write, make_folder_for

DEFAULT_FPS = 25
"""Frames per second of an animation unless asked otherwise (40 ms, which GIF's
hundredths of a second hold exactly)."""

ANIMATION_SIZE = (640, 480)
"""Pixels of an animation unless a size is given."""

ANIMATION_SUFFIXES = (".gif", ".mp4")

VIDEO_EXTRA = "pip install 'modalviewer[video]'"
"""The command installing the MP4 writer (imageio and imageio-ffmpeg, which ships an
ffmpeg binary)."""


def mp4_available() -> bool:
    """Whether MP4 can be written (imageio and imageio-ffmpeg installed)."""
    return all(importlib.util.find_spec(m) is not None for m in ("imageio", "imageio_ffmpeg"))


def period_frames(speed: float, fps: float) -> int:
    """Frames of one period at the window's animation ``speed`` (tenths of a radian per
    second) and ``fps``: the file plays at the speed the window shows (at least 8)."""
    period = 2.0 * np.pi / (float(speed) / 10.0)
    return max(8, int(round(period * float(fps))))


def frame_phases(frames: int) -> np.ndarray:
    """The phases (radians) of ``frames`` frames making one period that loops without a
    repeated frame, from the largest displacement (so the first frame, which viewers
    show before playing, is the mode's shape, not the rest shape).  A standing wave
    looks the same at phases mirrored about its peaks; with an odd count the frames
    start a quarter step past the peak, or two neighbouring frames would be the same
    picture (and a GIF writer merges them)."""
    n = int(frames)
    start = 0.5 * np.pi + (0.5 * np.pi / n if n % 2 else 0.0)
    return start + 2.0 * np.pi * np.arange(n) / n


def animation_path(path, size=None) -> Path:
    """``path`` checked as a .gif or a writable .mp4 of an even ``size`` (if given: MP4's
    H.264 4:2:0 needs an even width and height), its folder made; ValueError otherwise."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in ANIMATION_SUFFIXES:
        raise ValueError(f"{path.name}: animations are written as .gif or .mp4")
    if suffix == ".mp4" and not mp4_available():
        raise ValueError(
            f"{path.name}: writing MP4 needs imageio and imageio-ffmpeg ({VIDEO_EXTRA}); "
            "or write a .gif"
        )
    if suffix == ".mp4" and size is not None and (int(size[0]) % 2 or int(size[1]) % 2):
        raise ValueError(f"an MP4's width and height must be even, got {size[0]}x{size[1]}")
    make_folder_for(path)
    return path


def _write_gif(target, images, fps) -> None:
    from PIL import Image

    frames = [Image.fromarray(np.ascontiguousarray(img[..., :3])) for img in images]
    frames[0].save(
        target,
        format="GIF",
        save_all=True,
        append_images=frames[1:],
        duration=int(round(1000.0 / float(fps))),
        loop=0,
    )


def _write_mp4(path, images, fps) -> None:
    import imageio.v2 as imageio

    # macro_block_size=1: the frames keep their size (imageio would resize them to a
    # multiple of 16); quality 8 of 10
    writer = imageio.get_writer(
        str(path), format="FFMPEG", fps=float(fps), codec="libx264", quality=8, macro_block_size=1
    )
    try:
        for img in images:
            writer.append_data(np.ascontiguousarray(img[..., :3]))
    finally:
        writer.close()


def write_animation(path, images: list[np.ndarray], fps: float = DEFAULT_FPS) -> Path:
    """Write equal-sized RGB frames to ``path`` (.gif or .mp4) atomically; returns the path."""
    if not images:
        raise ValueError("an animation needs at least one frame")
    path = animation_path(path, (images[0].shape[1], images[0].shape[0]))
    write = _write_gif if path.suffix.lower() == ".gif" else _write_mp4
    return atomic_write(path, lambda tmp: write(tmp, images, fps))


class Animation:
    """A looping GIF of a vibration, shown inline by Jupyter (``_repr_html_``); ``.data``
    its bytes, :meth:`save` writes it (.gif; .mp4 from :attr:`frames` where imageio and
    imageio-ffmpeg are installed)."""

    def __init__(self, frames: list[np.ndarray], fps: float = DEFAULT_FPS):
        import io

        self.frames = frames
        self.fps = float(fps)
        out = io.BytesIO()
        _write_gif(out, frames, fps)
        self.data = out.getvalue()

    @property
    def size(self) -> tuple[int, int]:
        return int(self.frames[0].shape[1]), int(self.frames[0].shape[0])

    def _repr_html_(self) -> str:
        import base64

        encoded = base64.b64encode(self.data).decode("ascii")
        w, h = self.size
        return f'<img src="data:image/gif;base64,{encoded}" width="{w}" height="{h}">'

    def save(self, path) -> Path:
        """Write the animation to ``path`` (.gif or .mp4), atomically; returns the path."""
        return write_animation(path, self.frames, self.fps)

    def __repr__(self) -> str:
        w, h = self.size
        return f"Animation({len(self.frames)} frames, {w}x{h}, {self.fps:g} fps)"
