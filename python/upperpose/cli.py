"""The `upperpose` command line: one subcommand per module in `upperpose.commands`."""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading
from collections.abc import Sequence

import cv2

from upperpose import __version__
from upperpose.exceptions import UpperposeError, one_line

# Subcommand modules; each defines NAME, HELP, add_arguments(parser) and run(args) -> int.
COMMAND_MODULES = (
    "render",
    "features",
    "synth",
    "eval",
    "track",
    "batch",
    "config",
    "schema",
    "plot",
    "demo",
    "bench",
    "compare",
)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog="upperpose",
        description="3D upper-body pose from one ordinary camera, in real time, with no trained model.",
    )
    parser.add_argument("--version", action="version", version=f"upperpose {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        module = importlib.import_module(f"upperpose.commands.{name}")
        p = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        p.set_defaults(run=module.run)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the command line; returns the exit status (0 ok, 1 error, 2 usage, 130 interrupted).

    Errors about the input (bad files, bad values) print one line on stderr instead of a
    traceback; set UPPERPOSE_DEBUG=1 to see the traceback.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    # OpenCV and FFmpeg log their own warnings and errors (an unknown file extension, "moov atom
    # not found") on stderr; the command line reports each failure itself on one line.
    if not os.environ.get("UPPERPOSE_DEBUG"):
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")  # FFmpeg's own (AV_LOG_QUIET), read on first use
    if not getattr(args, "run", None):
        parser.print_help()
        return 2
    # SIGTERM (a job scheduler, `docker stop`) ends a run the way Ctrl-C does: outputs kept whole.
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _interrupt) if main_thread else None
    try:
        return _run(args)
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace) -> int:
    """Runs the subcommand; errors become one line on stderr and an exit status."""
    try:
        return int(args.run(args))
    except KeyboardInterrupt:
        print("upperpose: interrupted", file=sys.stderr)
        return 130
    except (UpperposeError, ValueError, TypeError, OSError, OverflowError, cv2.error) as err:
        if os.environ.get("UPPERPOSE_DEBUG"):
            raise
        print(f"upperpose {args.command}: error: {one_line(err)}", file=sys.stderr)
        return 1
    except Exception as err:  # a bug: still one line on the command line, the traceback on request
        if os.environ.get("UPPERPOSE_DEBUG"):
            raise
        print(
            f"upperpose {args.command}: internal error ({type(err).__name__}: {one_line(err)}); "
            "rerun with UPPERPOSE_DEBUG=1 for the traceback and please report it",
            file=sys.stderr,
        )
        return 1


def _interrupt(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


if __name__ == "__main__":
    sys.exit(main())
