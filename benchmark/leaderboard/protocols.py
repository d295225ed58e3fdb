"""The protocols a leaderboard accepts: manifest hashes, distances, conditions and environments.

Packaged in ``data/protocols.yaml``; a leaderboard folder may carry its own
``protocols.yaml`` (same format), which then replaces the packaged one, so a maintainer
can accept a new manifest without a release. A pull request can carry one too, so it is
read as untrusted text: at most 1 MiB of UTF-8 YAML without duplicate keys, anchors or
aliases (an alias of aliases, a "billion laughs", grows exponentially where a value is
printed), only the keys below (a misspelt key is an error, not a default), strings where
strings are meant.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import yaml

from metricscenes.files import read_text_capped
from metricscenes.manifest import UniqueKeyLoader

PROTOCOLS_FILE = "protocols.yaml"
MAX_PROTOCOLS_BYTES = 1 << 20
PROTOCOL_KEYS = ("description", "manifests_sha256", "distances_m", "conditions", "required_conditions",
                 "n_environments", "collection_names")


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

    def __post_init__(self):
        if not self.collection_names:
            object.__setattr__(self, "collection_names", (self.name,))


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


def _count(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"n_environments must be a positive integer, got {value!r}")
    return value


def _parse(text: str, source: str) -> dict[str, Protocol]:
    try:
        data = yaml.load(text, Loader=_PlainLoader)  # noqa: S506 (a SafeLoader)
        if not isinstance(data, dict) or not isinstance(data.get("protocols"), dict):
            raise ValueError("no 'protocols' mapping")
        unknown = sorted(map(str, set(data) - {"protocols"}))
        if unknown:
            raise ValueError(f"unknown top-level key(s) {', '.join(unknown)} (it holds only 'protocols')")
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


def load_protocols(leaderboard_dir: str | Path | None = None) -> dict[str, Protocol]:
    """Accepted protocols by name: ``leaderboard_dir/protocols.yaml`` if present, else the packaged list."""
    if leaderboard_dir is not None:
        local = Path(leaderboard_dir) / PROTOCOLS_FILE
        if local.is_file():
            return _parse(read_text_capped(local, MAX_PROTOCOLS_BYTES, "protocols file"), str(local))
    text = resources.files("benchmark.leaderboard").joinpath("data", PROTOCOLS_FILE).read_text(encoding="utf-8")
    return _parse(text, f"benchmark/leaderboard/data/{PROTOCOLS_FILE}")
