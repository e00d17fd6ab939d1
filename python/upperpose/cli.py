"""The `upperpose` command line: one subcommand per module in `upperpose.commands`."""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import signal
import sys
import threading
from collections.abc import Sequence

import cv2

from upperpose import __version__
from upperpose.commands.limits import OptionError
from upperpose.exceptions import UpperposeError, one_line
from upperpose.io.progress import write_line

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
    add_output_arguments(parser, top=True)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        module = importlib.import_module(f"upperpose.commands.{name}")
        p = sub.add_parser(module.NAME, help=module.HELP, description=module.HELP)
        module.add_arguments(p)
        add_output_arguments(p, top=False)
        p.set_defaults(run=module.run, usage_error=p.error)
    return parser


def add_output_arguments(p: argparse.ArgumentParser, top: bool) -> None:
    """-v and -q, before the subcommand or after it.

    A subcommand's defaults would overwrite the values given before it, so there they are unset.
    """
    p.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0 if top else argparse.SUPPRESS,
        help="say what happens (-v) and more (-vv)",
    )
    p.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        default=False if top else argparse.SUPPRESS,
        help="errors only: no warnings, progress or summary",
    )


class _LogLines(logging.Handler):
    """The package's log as lines `upperpose CMD: LEVEL: message` on stderr, above any progress bar."""

    def __init__(self, command: str) -> None:
        super().__init__()
        self.command = command

    def emit(self, record: logging.LogRecord) -> None:
        try:
            write_line(f"upperpose {self.command}: {record.levelname.lower()}: {record.getMessage()}", sys.stderr)
        except Exception:
            self.handleError(record)


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the command line; returns the exit status (0 ok, 1 error, 130 interrupted).

    Errors about the input (bad files, bad values) print one line on stderr instead of a
    traceback; set UPPERPOSE_DEBUG=1 to see the traceback. A bad option value raises
    SystemExit(2) after argparse's usage line, as argparse does. -v/-q set the level of the
    `upperpose` logger for the run.
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
    log = logging.getLogger("upperpose")
    level, handler = log.level, _LogLines(args.command)
    log.setLevel(logging.ERROR if args.quiet else max(logging.DEBUG, logging.WARNING - 10 * args.verbose))
    log.addHandler(handler)
    try:
        return _run(args)
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
        if main_thread:
            signal.signal(signal.SIGTERM, previous)


def _run(args: argparse.Namespace) -> int:
    """Runs the subcommand; errors become one line on stderr and an exit status."""
    try:
        return int(args.run(args))
    except KeyboardInterrupt:
        print("upperpose: interrupted", file=sys.stderr)
        return 130
    except OptionError as err:  # a bad option value: argparse's usage line and exit 2, as for a bad type
        args.usage_error(str(err))
        return 2  # not reached: error() exits
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
