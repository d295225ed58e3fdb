"""The scene subset of a quick try: ``--environments 0-2,5 --distances 25,50``.

:func:`parse_subset` reads the two options against a collection's scenes (one-line errors
naming what the collection has); :class:`CollectionSubset` is the collection seen through
the chosen environments × distances, and its ``subset`` marks every run made on it
(results.json ``subset``, the cache keys of :mod:`benchmark.experiments.keys`, ``+``:func:`subset_tag`
in a sweep's run folder names), so a subset run is never taken for a full one.
"""

from __future__ import annotations

import hashlib
import json


def _compact(values) -> str:
    """Sorted integers as ranges: [0, 1, 2, 5] → "0-2, 5"."""
    values, parts, start = sorted(values), [], None
    for i, v in enumerate(values):
        start = v if start is None else start
        if i + 1 == len(values) or values[i + 1] != v + 1:
            parts.append(f"{start}" if start == v else f"{start}-{v}")
            start = None
    return ", ".join(parts)


def _gaps(lo: int, hi: int, known: list[int]) -> list[str]:
    """The ids of lo..hi that are not in ``known`` (sorted), as ranges ("3-999999999"),
    without listing them one by one: a range may be as large as its user typed."""
    gaps, start = [], lo
    for k in (k for k in known if lo <= k <= hi):
        if k > start:
            gaps.append(f"{start}" if k - 1 == start else f"{start}-{k - 1}")
        start = k + 1
    if start <= hi:
        gaps.append(f"{start}" if start == hi else f"{start}-{hi}")
    return gaps


def _parse_environments(text: str, known: list[int]) -> list[int]:
    """The ids ``text`` names ("0-2,5"), each range bounded by the collection's ids before
    anything is listed (``0-999999999`` is refused in one line, not expanded)."""
    chosen: set[int] = set()
    unknown: list[str] = []
    for token in (t.strip() for t in str(text).split(",")):
        try:
            lo, _, hi = token.partition("-")
            lo_i, hi_i = int(lo), int(hi) if hi else int(lo)
        except ValueError:
            raise ValueError(f"--environments: {token!r} is neither an environment id nor a range "
                             "(e.g. --environments 0-2,5)") from None
        if hi_i < lo_i:
            raise ValueError(f"--environments: empty range {token!r}")
        chosen.update(k for k in known if lo_i <= k <= hi_i)
        unknown += _gaps(lo_i, hi_i, known)
    unknown = list(dict.fromkeys(unknown))
    if unknown:
        shown = ", ".join(unknown[:5]) + (", ..." if len(unknown) > 5 else "")
        raise ValueError(f"--environments {text}: unknown environment id(s) {shown} "
                         f"(this collection has {_compact(known)})")
    return sorted(chosen)


def _parse_distances(text: str, known: list[float]) -> list[float]:
    chosen: list[float] = []
    for token in (t.strip() for t in str(text).split(",")):
        try:
            value = float(token.removesuffix("m").strip())
        except ValueError:
            raise ValueError(f"--distances: {token!r} is not a distance in metres (e.g. --distances 25,50)") from None
        match = next((d for d in known if abs(d - value) < 1e-6), None)
        if match is None:
            raise ValueError(f"--distances: unknown distance {token} m "
                             f"(this collection has {', '.join(f'{d:g}' for d in known)} m)")
        if match not in chosen:
            chosen.append(match)
    return sorted(chosen)


def parse_subset(collection, environments: str | None = None, distances: str | None = None) -> dict | None:
    """The scenes a quick try keeps: ``environments`` such as ``"0-2,5"`` (ids and inclusive
    ranges) and ``distances`` such as ``"25,50"`` (metres), each None for all. Returns
    ``{"environments": [...], "distances_m": [...]}``, or None where nothing is left out
    (a "subset" of every scene is the full run). A one-line ValueError names an unknown id
    or distance and what the collection has, and a subset of fewer than two distances (no
    OD50 without an AP curve)."""
    if environments is None and distances is None:
        return None
    scenes = collection.scenes()
    known_envs = sorted({int(s.environment_id) for s in scenes})
    known_dists = sorted({float(s.distance_m) for s in scenes})
    envs = known_envs if environments is None else _parse_environments(environments, known_envs)
    dists = known_dists if distances is None else _parse_distances(distances, known_dists)
    if len(dists) < 2:  # OD50 is read off the AP curve between distances
        raise ValueError(f"--distances {distances}: a run needs two or more distances (the collection has "
                         f"{', '.join(f'{d:g}' for d in known_dists)} m)")
    if envs == known_envs and dists == known_dists:
        return None
    return {"environments": envs, "distances_m": dists}


def subset_tag(subset: dict) -> str:
    """Short, stable name of a subset for run folder names: ``subset-1a2b3c4d``."""
    return "subset-" + hashlib.sha256(json.dumps(subset, sort_keys=True).encode()).hexdigest()[:8]


class CollectionSubset:
    """A collection seen through a subset of its scenes (:func:`parse_subset`): ``scenes()``
    and ``groundtruth()`` keep only the chosen environments × distances; everything else is
    the collection's. Its ``subset`` attribute marks every run made on it (results.json
    ``subset``, the sweep cache key), so a subset run is never taken for a full one."""

    def __init__(self, collection, subset: dict):
        self._collection, self.subset = collection, subset
        self._envs = set(subset["environments"])

    def _keep(self, environment_id, distance_m) -> bool:
        return int(environment_id) in self._envs and any(abs(float(distance_m) - d) < 1e-6
                                                         for d in self.subset["distances_m"])

    def __getattr__(self, name):
        if name == "_collection":  # not set yet (a copy being unpickled in a sweep's worker)
            raise AttributeError(name)
        return getattr(self._collection, name)

    def scenes(self):
        return [s for s in self._collection.scenes() if self._keep(s.environment_id, s.distance_m)]

    def groundtruth(self) -> dict:
        gt = self._collection.groundtruth()
        gt["images"] = [im for im in gt["images"] if self._keep(im["environment_id"], im["distance_m"])]
        ids = {im["id"] for im in gt["images"]}
        gt["annotations"] = [a for a in gt["annotations"] if a["image_id"] in ids]
        return gt


def subset_collection(collection, environments: str | None = None, distances: str | None = None):
    """``collection`` itself, or a :class:`CollectionSubset` of it (see :func:`parse_subset`)."""
    subset = parse_subset(collection, environments, distances)
    return collection if subset is None else CollectionSubset(collection, subset)
