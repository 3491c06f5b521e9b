"""The error a sub-command raises for bad input of its own (kept apart from the command
modules so that the entry point catches it without importing them)."""

from __future__ import annotations


class UserError(Exception):
    """Bad input from the user: printed as one line on stderr, exit status 2."""
