"""Start the viewer: ``modalviewer [MESH]``.  Without a display (no ``DISPLAY`` or
``WAYLAND_DISPLAY`` on Linux), or with ``--screenshot PATH``, it opens the mesh,
computes a spectrum, writes a screenshot with the window's own export and exits,
saying so.
"""

from __future__ import annotations

import argparse
import gc
import logging
import os
import sys
import traceback
import weakref
from pathlib import Path

from ..cli.common import COUNT, MODE_INDEX
from ..core.operators import OPERATOR_NAMES
from ..scene.platform import has_display

log = logging.getLogger("modalviewer")


def _commands_epilog() -> str:
    """The headless subcommands with their one-line help, for ``modalviewer --help``."""
    from ..cli import build_parser as cli_parser

    sub = next(a for a in cli_parser()._actions if isinstance(a, argparse._SubParsersAction))
    lines = ["headless commands ('modalviewer COMMAND --help' shows their options):"]
    lines += [f"  {c.dest:<10} {c.help}" for c in sub._choices_actions]
    return "\n".join(lines)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="modalviewer",
        usage="%(prog)s [-h] [options] [mesh]\n       %(prog)s COMMAND ...",
        description="Modal shape analysis viewer.",
        epilog=_commands_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("mesh", nargs="?", help="mesh file to open (default: the bundled mesh)")
    p.add_argument(
        "--operator",
        choices=list(OPERATOR_NAMES),
        help="spectrum to compute at start (headless default: modified_dirichlet)",
    )
    p.add_argument("--mode", type=MODE_INDEX, help="mode to show (from 0)")
    p.add_argument("-k", type=COUNT, help="number of modes")
    p.add_argument("--screenshot", help="render to this PNG and exit")
    p.add_argument(
        "--partial",
        action="store_true",
        help="open a damaged or truncated file's whole records at once (without it the "
        "window asks; a run without a display refuses such a file)",
    )
    p.add_argument(
        "--session",
        help="restore a session file (File > Save Session) instead of opening a mesh",
    )
    return p


def _show_mode(window, spec, mode: int | None) -> None:
    """Show ``--mode`` once the window's spectrum is computed; one beyond its modes is
    said in the window, and the last mode is shown."""
    if mode is None or spec is None:
        return
    if mode >= spec.k:
        window.show_error(f"--mode {mode}: the spectrum has modes 0 to {spec.k - 1}")
    window.show_mode(min(mode, spec.k - 1))


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    headless = args.screenshot is not None or not has_display()
    if headless and "QT_QPA_PLATFORM" not in os.environ:
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    if headless:  # nobody is there to answer a question: each is answered No
        os.environ["MODALVIEWER_NO_DIALOGS"] = "1"
        os.environ.pop("MODALVIEWER_ASSUME_YES", None)
    from .application import ensure_application
    from .dialogs import DAMAGED_WORDS
    from .main_window import MainWindow
    from .paths import DEFAULT_MESH, SCREENSHOTS

    app = ensure_application()
    window = MainWindow()

    window_ref = weakref.ref(window)

    def excepthook(kind, value, tb):  # slots must never take the app down
        details = "".join(traceback.format_exception(kind, value, tb))
        log.error("unexpected error:\n%s", details)
        current = window_ref()
        if current is not None:
            current.show_error(f"Unexpected error: {value}. The details are in the log.")

    sys.excepthook = excepthook
    if headless:
        window.resize(1500, 900)
    window.show()
    app.processEvents()
    out = Path(args.screenshot) if args.screenshot else SCREENSHOTS / "headless_run.png"
    if args.session:
        notes = window.open_session(args.session, wait=headless)
        if window.state.mesh is None:
            print(f"modalviewer: error: {window.last_error}", file=sys.stderr)
            if headless:
                return 1
        if not headless:
            return app.exec()
        said = [f"note: {note}" for note in notes] + [f"session {args.session}: screenshot {out}"]
    else:
        path = Path(args.mesh) if args.mesh else DEFAULT_MESH
        opened = window.open_mesh(path, strict=not args.partial)
        if not headless:
            if opened and args.operator:
                then = lambda s: _show_mode(window, s, args.mode)  # noqa: E731
                window.compute(args.operator, k=args.k, wait=False, then=then)
            return app.exec()
        if not opened:
            print(f"modalviewer: error: {window.last_error}", file=sys.stderr)
            if str(window.last_error).endswith(DAMAGED_WORDS):
                print(
                    "modalviewer: note: --partial opens the file's whole records", file=sys.stderr
                )
            return 1
        if args.partial:  # what was dropped
            print(window.mesh.report)
        operator = args.operator or "modified_dirichlet"
        if args.screenshot is None:
            print(
                "No display found: running the viewer off-screen on "
                f"{path.name} and saving a screenshot instead."
            )
        try:
            spec = window.compute(operator, k=args.k, wait=True)
        except Exception as exc:  # ComputeError carries the user message
            print(f"modalviewer: error: {exc}", file=sys.stderr)
            return 1
        if args.mode is not None and args.mode >= spec.k:  # as argparse's own errors
            print(f"modalviewer: error: --mode must be between 0 and {spec.k - 1}", file=sys.stderr)
            return 2
        if args.mode is not None:
            window.show_mode(args.mode)
        nonzero = spec.eigenvalues[~spec.zero_mode_mask()][:6]
        said = [
            f"{path.name}: {window.mesh.n_vertices} vertices; {operator}: {spec.k} modes; "
            f"lowest non-zero eigenvalues {', '.join(f'{x:.5g}' for x in nonzero)}",
            f"screenshot: {out}",
        ]
    app.processEvents()
    window.export_screenshot(out)
    print("\n".join(said))
    window.close()
    window = None  # drop the last reference before collecting
    gc.collect()  # release VTK objects before the interpreter shuts down
    return 0
