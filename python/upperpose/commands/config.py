"""`upperpose config`: print the effective tracker settings as TOML (defaults included)."""

from __future__ import annotations

import argparse

from upperpose.commands.track import add_search_arguments

NAME = "config"
HELP = "print the effective tracker settings as TOML (a settings file for `upperpose track --config`)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Options of the subcommand: the same settings options as `track`."""
    add_search_arguments(p)
    p.add_argument("--no-skip", action="store_true", help="search every part every frame (ignore the motion flags)")


def run(args: argparse.Namespace) -> int:
    """Prints the settings `upperpose track` would use with the same options."""
    from upperpose.commands.track import tracker_config
    from upperpose.fit.settings import config_to_toml

    print(config_to_toml(tracker_config(args)), end="")
    return 0
