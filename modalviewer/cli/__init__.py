"""Headless commands: ``modalviewer compute | render | distance | figures | batch |
similar``, one module and one function per command (``set_defaults(func=...)``).

Bad arguments and bad files give a one-line error and exit code 2 (usage) or 1
(input or computation), never a traceback.
"""

from __future__ import annotations

import argparse
import sys

from . import batch, compute, distance, render
from .common import BAR, BadArgument, Parser, Unavailable, joined_dash_values

COMMANDS = ("compute", "render", "distance", "figures", "batch", "similar")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="modalviewer", description="Headless modal shape analysis.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    compute.add_parsers(sub)
    render.add_parsers(sub)
    distance.add_parsers(sub)
    render.add_figures_parser(sub)
    batch.add_parsers(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(joined_dash_values(argv))
    from ..core.eigen import Cancelled

    try:
        return args.func(args)
    except KeyboardInterrupt:
        sys.stderr.write("modalviewer: interrupted\n")
        return 130
    except Cancelled:
        return 130
    except (Unavailable, BadArgument) as exc:
        _error(str(exc))
        return 2
    except (ValueError, OSError, RuntimeError, MemoryError) as exc:
        from ..repair import repair_for_failure

        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if repair_for_failure(message) == "fix_slivers" and not getattr(args, "fix_slivers", False):
            message += "; retry with --fix-slivers"
        _error(message)
        return 1


def _error(message: str) -> None:
    if BAR["open"]:  # a progress line stopped short
        sys.stderr.write("\n")
    sys.stderr.write(f"modalviewer: error: {message}\n")
