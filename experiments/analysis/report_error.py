"""The one error of reading results into tables: a batch that cannot be reported on."""

from __future__ import annotations


class ReportError(Exception):
    """A batch that cannot be reported on; the message (one line) says why."""
