"""Sessions: the viewer state to and from a versioned JSON file (no Qt).

A session stores the mesh file (path and hash), the spectra's keys (the arrays come
back from the cache, or are recomputed) and the display, so restoring it draws the same
picture; a changed mesh file, or what no longer fits, gets a note.
"""

from __future__ import annotations

import json
import os
from contextlib import suppress
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

from ..core.files import atomic_write
from .jobs import Job
from .process import repair_in_process
from .state import ComputeSettings, Display, SpectrumKey, ViewerState

FORMAT = "modalviewer-session"
STYLE = ("isolines", "shell_coloring", "colorbar", "render", "ghost")
COLOR_RANGE = ("color_range", "color_limits")  # set together (ViewerState.set_color_range)
VERSION = 2  # 2: "picked" is the file's vertex number (1: the loaded mesh's index)


class SessionError(ValueError):
    """A session file is unreadable, foreign, or from a newer version."""


@dataclass
class Restored:
    """What :func:`restore_session` started and what it could not restore as saved."""

    jobs: list[Job] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def session_dict(state: ViewerState, base: Path | None = None) -> dict:
    """The state as plain data; mesh paths also relative to ``base``, so a session moved
    with its mesh still finds it."""
    if state.mesh is None:
        raise ValueError("no mesh is loaded: nothing to save")
    path = Path(state.mesh_path).resolve() if state.mesh_path else None
    relative = None
    if path is not None and base is not None:
        with suppress(ValueError):  # none from another drive (Windows)
            relative = os.path.relpath(path, base)
    return {
        "format": FORMAT,
        "version": VERSION,
        "mesh": {
            "path": str(path) if path else None,
            "relative_path": relative,
            "hash": state.mesh.hash,
            "vertices": state.mesh.n_vertices,
            "file_vertices": state.mesh.n_file_vertices,
            "repairs": list(state.mesh_repairs),
        },
        "spectra": [asdict(key) for key in state.spectra],
        "compute_settings": asdict(state.compute_settings),
        "display": asdict(state.display),
        "picked": state.picked_file_vertex,  # the file's number
        "t_range": list(state.t_range) if state.t_range else None,
        "style": {name: getattr(state.style, name) for name in (*STYLE, *COLOR_RANGE)},
        "animation": {"amplitude": state.animation.amplitude, "speed": state.animation.speed},
        "camera": state.camera,
        "up_axis": state.up_axis,  # None: the detected one
    }


def save_session(state: ViewerState, path) -> Path:
    """Write the session to ``path`` atomically; returns the path."""
    path = Path(path)
    data = session_dict(state, base=path.resolve().parent)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(data, indent=2)
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), ".part")


def read_session(path) -> dict:
    """The session file's data, checked for format and version."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SessionError(f"{path} does not exist") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SessionError(f"{path.name} is not a readable session file ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise SessionError(f"{path.name} is not a modalviewer session file")
    if int(data.get("version", 0)) > VERSION:
        raise SessionError(
            f"{path.name} was written by a newer modalviewer (session version "
            f"{data['version']}; this one reads up to {VERSION})"
        )
    return data


def _known(cls, values: dict) -> dict:
    names = {f.name for f in fields(cls)}
    return {k: v for k, v in (values or {}).items() if k in names}


def _update(evented, values: dict | None, names=None) -> None:
    """Set the fields of ``evented`` that ``values`` has (of ``names`` only, if given)."""
    for name, value in _known(type(evented), values).items():
        if names is None or name in names:
            setattr(evented, name, value)


def restore_session(model, path) -> Restored:
    """Open the session's mesh and restore its state in ``model``: the spectra are
    requested (the returned jobs) and the display is set once they are in."""
    path = Path(path)
    data = read_session(path)
    out = Restored()
    mesh_info = data.get("mesh") or {}
    candidates = []
    if mesh_info.get("relative_path"):
        candidates.append((path.resolve().parent / mesh_info["relative_path"]).resolve())
    if mesh_info.get("path"):
        candidates.append(Path(mesh_info["path"]))
    mesh_path = next((p for p in candidates if p.is_file()), None)
    if mesh_path is None:
        raise SessionError(
            f"the session's mesh {mesh_info.get('path') or '(none)'} cannot be found"
        )
    mesh = model.open_mesh(mesh_path)
    state = model.state
    repairs = [str(r) for r in mesh_info.get("repairs") or []]
    if repairs:
        # re-applied here, in order, each in a child process (see .process); a sliver
        # repair of a big scan takes seconds
        for name in repairs:
            mesh = repair_in_process(name, mesh, lambda *_: None, lambda: False)
        model.set_mesh(mesh, mesh_path, repairs)
    if state.mesh.hash != mesh_info.get("hash"):  # the hash saved is the state's mesh's
        out.notes.append(
            f"{mesh_path.name} changed on disk since the session was saved: spectra are "
            "recomputed and the pick may point elsewhere"
        )
    style = {"colorbar": True, "render": "paper", "ghost": True, **(data.get("style") or {})}
    _update(state.style, style, STYLE)
    state.set_color_range(str(style.get("color_range", "auto")), style.get("color_limits"))
    _update(state.animation, data.get("animation"))
    settings = ComputeSettings()  # the saved fields that are valid, the defaults elsewhere
    for name, value in _known(ComputeSettings, data.get("compute_settings")).items():
        try:
            setattr(settings, name, value)
        except (TypeError, ValueError) as exc:
            out.notes.append(f"the compute setting {name} = {value!r}: {exc}; default used")
    _update(state.compute_settings, asdict(settings))
    if data.get("t_range"):
        state.set_scale_range(tuple(data["t_range"]))
    try:
        state.up_axis = data.get("up_axis")
    except ValueError as exc:
        out.notes.append(f"the up axis: {exc}")
    picked = data.get("picked")
    if picked is not None and int(data.get("version", 1)) >= 2:
        try:  # the file's vertex number
            state.set_pick_file_vertex(int(picked))
        except ValueError as exc:
            out.notes.append(f"the picked vertex {picked}: {exc}; pick again")
    elif picked is not None:  # version 1: the index in the mesh as loaded then
        if 0 <= int(picked) < mesh.n_vertices:
            state.set_pick(int(picked))
        else:
            out.notes.append(f"the picked vertex {picked} is not on this mesh; pick again")
    saved_display = dict(data.get("display") or {})
    if "threshold_by_share" in saved_display:  # the name keep_share had in older files
        saved_display.setdefault("keep_share", saved_display.pop("threshold_by_share"))
    display = Display(**_known(Display, saved_display))
    for raw in data.get("spectra") or []:
        try:  # the key as the compute settings make it (validated, weights where used)
            key = ComputeSettings(**asdict(SpectrumKey(**_known(SpectrumKey, raw)))).key()
            out.jobs.append(model.request_spectrum(key=key))
        except (TypeError, ValueError) as exc:  # a TypeError names a missing field
            out.notes.append(f"the saved spectrum {raw} is not computed: {exc}")
    camera = data.get("camera")

    def apply_display(_job=None) -> None:
        if not all(job.done for job in out.jobs):
            return
        try:
            state.set_display(**asdict(display))
        except ValueError as exc:
            out.notes.append(f"the saved display cannot be shown: {exc}")
        if camera:
            state.camera = camera

    for job in out.jobs:
        job.then(apply_display)
    if not out.jobs:
        apply_display()
    return out
