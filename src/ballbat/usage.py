"""The command line's error for a bad argument, below ``ballbat.cli`` and the commands it registers."""

from __future__ import annotations

__all__ = ["UsageError"]


class UsageError(Exception):
    """A bad argument: reported as one line, exit status 2."""
