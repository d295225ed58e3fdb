"""The submission JSON Schema (``data/submission.schema.json``, draft 2020-12) and strict JSON reading.

Strict reading refuses what Python's ``json`` would quietly accept but other readers
would not: ``NaN``/``Infinity`` literals, numbers that overflow a 64-bit float (``1e400``
is Infinity in disguise), duplicate object keys (RFC 8259 §4: names "SHOULD be unique"),
strings that are not valid Unicode (a lone surrogate ``\\ud800`` cannot be written as
UTF-8) and nesting deeper than :data:`MAX_DEPTH` levels.
"""

from __future__ import annotations

import json
import math
import re
import unicodedata
from functools import lru_cache
from importlib import resources

import jsonschema

SUBMISSION_FORMAT = "metricscenes-submission/1"
SCHEMA_FILE = "submission.schema.json"
MAX_DEPTH = 32  # a submission nests 6 levels, a camera spec a few more
MULTILINE_FIELDS = (("notes",),)  # the only strings that may hold line breaks and tabs


class SubmissionError(ValueError):
    """A submission (or its inputs) is malformed or inconsistent; the message is one line."""


def schema_text() -> str:
    """The packaged schema, verbatim (what ``benchmark schema submission`` prints)."""
    return resources.files("benchmark.leaderboard").joinpath("data", SCHEMA_FILE).read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def submission_schema() -> dict:
    return json.loads(schema_text())


def _no_constants(name: str):
    raise SubmissionError(f"invalid JSON: non-standard literal {name} (use null)")


def _unique_keys(pairs: list[tuple[str, object]]) -> dict:
    out: dict = {}
    for key, value in pairs:
        if key in out:
            raise SubmissionError(f"invalid JSON: duplicate key {key!r}")
        out[key] = value
    return out


def _finite_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise SubmissionError(f"invalid JSON: number {text[:24]} overflows to infinity (numbers must be finite)")
    return value


def _float_sized_int(text: str) -> int:
    try:
        value = int(text)
        float(value)
    except (ValueError, OverflowError):  # over 4300 digits, or beyond a 64-bit float
        raise SubmissionError(f"invalid JSON: integer {text[:24]}{'...' if len(text) > 24 else ''} is too large") from None
    return value


def loads_strict(raw: bytes | str, source: str = "submission") -> object:
    """Parse JSON, refusing NaN/Infinity (also as ``1e400``), duplicate keys, deep nesting and
    invalid Unicode (:func:`check_values`); one-line :class:`SubmissionError`."""
    try:
        text = raw.decode("utf-8") if isinstance(raw, bytes) else raw
    except UnicodeDecodeError as exc:
        raise SubmissionError(f"{source}: invalid JSON: not UTF-8 (byte {exc.start})") from None
    try:
        data = json.loads(text, parse_constant=_no_constants, parse_float=_finite_float, parse_int=_float_sized_int,
                          object_pairs_hook=_unique_keys)  # fmt: skip
    except json.JSONDecodeError as exc:
        raise SubmissionError(f"{source}: invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}") from None
    except RecursionError:
        raise SubmissionError(f"{source}: invalid JSON: nested deeper than {MAX_DEPTH} levels") from None
    except SubmissionError as exc:
        raise SubmissionError(f"{source}: {exc}") from None
    check_values(data, source)
    return data


# C0 and C1 controls (category Cc), line and paragraph separators (Zl, Zp), surrogates (Cs)
_BAD_CHAR = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")
_BAD_CHAR_MULTILINE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")  # \t and \n allowed


def _format_char(text: str) -> str | None:
    """The first invisible formatting character of ``text`` (Unicode category Cf: the
    bidirectional overrides, embeddings and isolates that make "21mac" read as "cam12", zero-width
    spaces and joiners, the byte-order mark), described; None if there is none."""
    if text.isascii():
        return None
    for ch in text:
        if unicodedata.category(ch) == "Cf":
            return f"an invisible formatting character U+{ord(ch):04X} ({unicodedata.name(ch, 'unnamed').lower()})"
    return None


def _bad_char(text: str, multiline: bool = False) -> str | None:
    """What is wrong with the first character of ``text`` that has no place in a submission string, if any."""
    found = (_BAD_CHAR_MULTILINE if multiline else _BAD_CHAR).search(text)
    if found is None:
        return _format_char(text)
    code = ord(found.group())
    if 0xD800 <= code <= 0xDFFF:
        return f"a lone surrogate U+{code:04X} (not valid Unicode; UTF-8 cannot encode it)"
    return f"a control character or line break U+{code:04X}"


def check_values(data: object, source: str = "submission") -> None:
    """Refuse nesting deeper than :data:`MAX_DEPTH`, numbers that are not finite, and strings
    (keys too) holding a lone surrogate (UTF-8 cannot encode it), a control character, a line
    break (``notes`` may hold line breaks and tabs) or an invisible formatting character (a
    right-to-left override: text that reads otherwise than it is). Iterative, so any depth is refused
    with one line, never a RecursionError."""
    stack: list[tuple[tuple, object]] = [((), data)]
    while stack:
        path, value = stack.pop()
        if len(path) > MAX_DEPTH:
            raise SubmissionError(f"{source}: invalid JSON: nested deeper than {MAX_DEPTH} levels")
        if isinstance(value, dict):
            for key in value:
                bad = _bad_char(key) if isinstance(key, str) else None
                if bad:
                    raise SubmissionError(f"{source}: {_where(path)}: a key holds {bad}")
            stack.extend(((*path, k), v) for k, v in reversed(value.items()))
        elif isinstance(value, (list, tuple)):
            stack.extend(((*path, i), v) for i, v in reversed(list(enumerate(value))))
        elif isinstance(value, float) and not math.isfinite(value):
            raise SubmissionError(f"{source}: {_where(path)}: {value} is not a finite number (use null)")
        elif isinstance(value, str):
            bad = _bad_char(value, path in MULTILINE_FIELDS)
            if bad:
                raise SubmissionError(f"{source}: {_where(path)}: string holds {bad}")


def _where(path) -> str:
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "(top level)"


def check_schema(data: object, source: str = "submission") -> None:
    """Raise :class:`SubmissionError` naming the first (most relevant) schema violation."""
    validator = jsonschema.Draft202012Validator(submission_schema())
    error = jsonschema.exceptions.best_match(validator.iter_errors(data))
    if error is None:
        return
    message = " ".join(error.message.split())
    if len(message) > 160:
        message = message[:157] + "..."
    raise SubmissionError(f"{source}: schema: {_where(error.absolute_path)}: {message}")
