"""Subcommands of the `upperpose` command line, one module each."""
