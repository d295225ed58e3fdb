"""The submission JSON Schema (``data/submission.schema.json``, draft 2020-12) and strict JSON reading.

Strict reading refuses what Python's ``json`` would quietly accept but other readers
would not: ``NaN``/``Infinity`` literals and duplicate object keys (RFC 8259 §4: names
"SHOULD be unique").
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources

import jsonschema

SUBMISSION_FORMAT = "metricscenes-submission/1"
SCHEMA_FILE = "submission.schema.json"


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


def loads_strict(raw: bytes | str, source: str = "submission") -> object:
    """Parse JSON, refusing NaN/Infinity and duplicate keys; one-line :class:`SubmissionError`."""
    try:
        text = raw.decode("utf-8") if isinstance(raw, bytes) else raw
    except UnicodeDecodeError as exc:
        raise SubmissionError(f"{source}: invalid JSON: not UTF-8 (byte {exc.start})") from None
    try:
        return json.loads(text, parse_constant=_no_constants, object_pairs_hook=_unique_keys)
    except json.JSONDecodeError as exc:
        raise SubmissionError(f"{source}: invalid JSON at line {exc.lineno} column {exc.colno}: {exc.msg}") from None
    except SubmissionError as exc:
        raise SubmissionError(f"{source}: {exc}") from None


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
