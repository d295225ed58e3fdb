"""What a command printed on standard error, less its progress lines.

Off a terminal (a test's pipe), generate, run and sweep print a plain progress line every
5 % of their units or every 30 s (:class:`metricscenes.cli_support.LogProgress`), so a
refusal that comes after work began follows such lines on a slow machine. A test of the
one-line error counts the other lines.
"""

from __future__ import annotations

import re

_DURATION = r"(\d+ min \d{2} s|\d+ h \d{2} min)"  # cli_support._duration
PROGRESS_LINE = re.compile(rf"(?!error: ).+: (\S+/\S+ \(\d+ %\)|\S+ done), {_DURATION} elapsed(, about {_DURATION} left)?")


def error_lines(stderr: str) -> list[str]:
    """The non-blank lines of ``stderr`` that are not progress lines."""
    return [line for line in stderr.splitlines() if line.strip() and not PROGRESS_LINE.fullmatch(line)]
