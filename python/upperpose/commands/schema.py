"""`upperpose schema`: print the pose file's JSON Schema."""

from __future__ import annotations

import argparse
import json

NAME = "schema"
HELP = "print the JSON Schema of the pose file (validate outputs with any JSON Schema library)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    """No options."""


def run(args: argparse.Namespace) -> int:
    """Prints the schema."""
    from upperpose.io.posefile import schema

    print(json.dumps(schema(), indent=2))
    return 0
