"""The protocols a leaderboard accepts: manifest hashes, distances, conditions and environments.

Packaged in ``data/protocols.yaml``; a leaderboard folder may carry its own
``protocols.yaml`` (same format), which then replaces the packaged one, so a maintainer
can accept a new manifest without a release.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import yaml

PROTOCOLS_FILE = "protocols.yaml"


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


def _count(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise ValueError(f"n_environments must be a positive integer, got {value!r}")
    return value


def _parse(text: str, source: str) -> dict[str, Protocol]:
    try:
        data = yaml.safe_load(text)
        out = {}
        for name, p in data["protocols"].items():
            out[str(name)] = Protocol(
                name=str(name),
                description=str(p.get("description", "")),
                manifests_sha256=tuple(str(h) for h in p["manifests_sha256"]),
                distances_m=tuple(float(d) for d in p["distances_m"]),
                conditions=tuple(str(c) for c in p["conditions"]),
                required_conditions=tuple(str(c) for c in p["required_conditions"]),
                n_environments=None if p.get("n_environments") is None else _count(p["n_environments"]),
            )
    except (yaml.YAMLError, KeyError, TypeError, AttributeError, ValueError) as exc:
        raise ValueError(f"{source}: invalid protocols file ({type(exc).__name__}: {exc})".splitlines()[0]) from None
    return out


def load_protocols(leaderboard_dir: str | Path | None = None) -> dict[str, Protocol]:
    """Accepted protocols by name: ``leaderboard_dir/protocols.yaml`` if present, else the packaged list."""
    if leaderboard_dir is not None:
        local = Path(leaderboard_dir) / PROTOCOLS_FILE
        if local.is_file():
            return _parse(local.read_text(encoding="utf-8"), str(local))
    text = resources.files("benchmark.leaderboard").joinpath("data", PROTOCOLS_FILE).read_text(encoding="utf-8")
    return _parse(text, f"benchmark/leaderboard/data/{PROTOCOLS_FILE}")
