"""The protocols a leaderboard accepts: manifest hashes, distances, conditions and environments;
which submissions are its references; and what each condition physically is (its label).

Packaged in ``data/protocols.yaml``; a leaderboard folder may carry its own
``protocols.yaml`` (same format), which then replaces the packaged one, so a maintainer
can accept a new manifest without a release. A pull request can carry one too, so it is
read as untrusted text: at most 1 MiB of UTF-8 YAML without duplicate keys, anchors or
aliases (an alias of aliases, a "billion laughs", grows exponentially where a value is
printed), only the keys below (a misspelt key is an error, not a default), strings where
strings are meant.

``labels`` (top level) names each condition by what it physically is; :func:`condition_label`
is the one place tables, figures and verdicts take a condition's name from (the key where
none is given). A leaderboard's own file without ``labels`` keeps the packaged ones.
"""

from __future__ import annotations

import fnmatch
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path

import yaml

from metricscenes.files import read_text_capped
from metricscenes.manifest import UniqueKeyLoader

PROTOCOLS_FILE = "protocols.yaml"
MAX_PROTOCOLS_BYTES = 1 << 20
PROTOCOL_KEYS = ("description", "manifests_sha256", "distances_m", "conditions", "required_conditions",
                 "n_environments", "collection_names", "references", "made_before_detections")
TOP_KEYS = ("labels", "protocols")
MAX_LABEL_CHARS = 80  # a column header, a figure title


@dataclass(frozen=True)
class Protocol:
    """One accepted protocol (a family of collection manifests)."""

    name: str
    description: str
    manifests_sha256: tuple[str, ...]
    distances_m: tuple[float, ...]
    conditions: tuple[str, ...]
    required_conditions: tuple[str, ...]
    n_environments: int | None = None  # environments of the collection; None: not checked
    collection_names: tuple[str, ...] = ()  # the names its manifests give their collections; () : the protocol's name
    references: str | None = None  # glob of its reference submissions' names (the band they draw); None: none
    # submissions made before detections shipped, accepted without them: name -> sha256 of the canonical JSON
    made_before_detections: dict[str, str] = field(default_factory=dict, hash=False)
    labels: dict[str, str] = field(default_factory=dict, hash=False, compare=False)  # condition -> what it is

    def __post_init__(self):
        if not self.collection_names:
            object.__setattr__(self, "collection_names", (self.name,))

    def label(self, condition: str) -> str:
        """What ``condition`` physically is (:func:`condition_label` with this file's labels)."""
        return condition_label(condition, self.labels)

    def is_reference(self, name: str) -> bool:
        """Whether a submission of this protocol named ``name`` is one of its references."""
        return self.references is not None and fnmatch.fnmatchcase(name, self.references)


class _PlainLoader(UniqueKeyLoader):
    """A YAML loader that refuses duplicate keys, anchors and aliases (a protocols file needs none)."""

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            raise yaml.composer.ComposerError(None, None, "an alias (*name): a protocols file holds none",
                                              self.peek_event().start_mark)
        return super().compose_node(parent, index)


def _text(value, what: str) -> str:
    if not isinstance(value, str):
        raise ValueError(f"{what} must be a string, got {type(value).__name__}")
    return value


def _texts(value, what: str) -> tuple[str, ...]:
    if not isinstance(value, list):
        raise ValueError(f"{what} must be a list, got {type(value).__name__}")
    return tuple(str(v) for v in value)


def _mapping(value, what: str, check_value) -> dict[str, str]:
    if not isinstance(value, dict):
        raise ValueError(f"{what} must be a mapping, got {type(value).__name__}")
    return {str(k): check_value(v, f"{what}.{k}") for k, v in value.items()}


def _label_text(value, what: str) -> str:
    from benchmark.leaderboard.schema import _bad_char

    text = _text(value, what)
    bad = _bad_char(text)
    if bad or not text.strip() or len(text) > MAX_LABEL_CHARS:
        raise ValueError(f"{what} must be 1-{MAX_LABEL_CHARS} printable characters" + (f" (it holds {bad})" if bad else ""))
    return text


def _sha256_text(value, what: str) -> str:
    text = _text(value, what)
    if len(text) != 64 or any(c not in "0123456789abcdef" for c in text):
        raise ValueError(f"{what} must be a sha256 (64 lowercase hex digits)")
    return text


def _count(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"n_environments must be a positive integer, got {value!r}")
    return value


def _parse(text: str, source: str, default_labels: dict[str, str] | None = None) -> dict[str, Protocol]:
    try:
        data = yaml.load(text, Loader=_PlainLoader)  # noqa: S506 (a SafeLoader)
        if not isinstance(data, dict) or not isinstance(data.get("protocols"), dict):
            raise ValueError("no 'protocols' mapping")
        unknown = sorted(map(str, set(data) - set(TOP_KEYS)))
        if unknown:
            raise ValueError(f"unknown top-level key(s) {', '.join(unknown)} (it holds only {', '.join(map(repr, TOP_KEYS))})")
        labels = (_mapping(data["labels"], "labels", _label_text) if "labels" in data
                  else dict(default_labels or {}))
        out = {}
        for name, p in data["protocols"].items():
            if not isinstance(p, dict):
                raise ValueError(f"protocol {name!r} must be a mapping")
            unknown = sorted(map(str, set(p) - set(PROTOCOL_KEYS)))
            if unknown:
                raise ValueError(f"protocol {name!r}: unknown key(s) {', '.join(unknown)} (known: {', '.join(PROTOCOL_KEYS)})")
            out[str(name)] = Protocol(
                name=str(name),
                description=_text(p.get("description", ""), f"protocol {name!r}: description"),
                manifests_sha256=_texts(p["manifests_sha256"], f"protocol {name!r}: manifests_sha256"),
                distances_m=tuple(float(d) for d in p["distances_m"]),
                conditions=_texts(p["conditions"], f"protocol {name!r}: conditions"),
                required_conditions=_texts(p["required_conditions"], f"protocol {name!r}: required_conditions"),
                n_environments=None if p.get("n_environments") is None else _count(p["n_environments"]),
                collection_names=_texts(p.get("collection_names", []), f"protocol {name!r}: collection_names"),
                references=None if p.get("references") is None else _text(p["references"], f"protocol {name!r}: references"),
                made_before_detections=_mapping(p.get("made_before_detections", {}),
                                                f"protocol {name!r}: made_before_detections", _sha256_text),
                labels=labels,
            )
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f" at line {mark.line + 1}" if mark else ""
        raise ValueError(f"{source}: invalid protocols file ({exc.problem}{where})".splitlines()[0]) from None
    except KeyError as exc:
        raise ValueError(f"{source}: invalid protocols file (missing key {exc})") from None
    except ValueError as exc:
        raise ValueError(f"{source}: invalid protocols file ({exc})".splitlines()[0]) from None
    except (yaml.YAMLError, TypeError, AttributeError, RecursionError) as exc:
        raise ValueError(f"{source}: invalid protocols file ({type(exc).__name__}: {exc})".splitlines()[0]) from None
    return out


@lru_cache(maxsize=1)
def _packaged() -> dict[str, Protocol]:
    text = resources.files("benchmark.leaderboard").joinpath("data", PROTOCOLS_FILE).read_text(encoding="utf-8")
    return _parse(text, f"benchmark/leaderboard/data/{PROTOCOLS_FILE}")


def packaged_labels() -> dict[str, str]:
    """The packaged condition labels: condition -> what it physically is."""
    return dict(next(iter(_packaged().values())).labels) if _packaged() else {}


def condition_label(condition: str, labels: dict[str, str] | None = None) -> str:
    """What ``condition`` physically is ("night" -> "0.1–1 lux image plane, sky raised"): from
    ``labels``, by default the packaged ``protocols.yaml``'s; the key itself where none is given."""
    return (packaged_labels() if labels is None else labels).get(condition, condition)


def load_protocols(leaderboard_dir: str | Path | None = None) -> dict[str, Protocol]:
    """Accepted protocols by name: ``leaderboard_dir/protocols.yaml`` if present, else the packaged list."""
    if leaderboard_dir is not None:
        local = Path(leaderboard_dir) / PROTOCOLS_FILE
        if local.is_file():
            return _parse(read_text_capped(local, MAX_PROTOCOLS_BYTES, "protocols file"), str(local), packaged_labels())
    return dict(_packaged())
