""""Did you mean": the nearest valid name for a mistyped one, suggested, never taken.

A refusal that names an unknown camera, condition or other name appends
:func:`did_you_mean`'s text: the valid name that differs only in case first
(``CAM12`` → ``cam12``, ``Night`` → ``night``), else the closest by spelling (``nite`` →
``night``, difflib's ratio ≥ 0.6). The command still refuses: a name is never silently
replaced by another.
"""

from __future__ import annotations

import difflib
from typing import Iterable


def closest_name(value: str, choices: Iterable[str], guess: str | None = None) -> str | None:
    """The valid name ``value`` most likely meant, or None. ``guess``: a caller's own
    normal spelling of ``value`` (``cam1`` → ``cam01``), taken first where it is valid."""
    choices = [str(c) for c in choices]
    if guess is not None and guess in choices:
        return guess
    text = str(value).strip()
    same_case = [c for c in choices if c.lower() == text.lower()]
    if same_case:
        return same_case[0]
    close = difflib.get_close_matches(text.lower(), [c.lower() for c in choices], n=1, cutoff=0.6)
    if not close:
        return None
    return next(c for c in choices if c.lower() == close[0])


def did_you_mean(value: str, choices: Iterable[str], guess: str | None = None) -> str:
    """``"; did you mean 'night'?"`` (to append to a one-line refusal), or ``""``."""
    name = closest_name(value, choices, guess)
    return "" if name is None or name == value else f"; did you mean {name!r}?"
