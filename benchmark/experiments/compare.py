"""``benchmark compare A B``: is camera A's detection range different from camera B's?

A and B are run folders (``results.json``, ``detections.json``, ``groundtruth.json``) or
sweep folders with ``--camera`` (and ``--condition``). Both must come from the same
collection (manifest sha256) and hold the same environments and distances; otherwise the
comparison is refused, since a difference would mix camera and scenes.

**Paired bootstrap.** Environments are resampled with replacement *once* per resample and
the same draw is applied to A and B (the design of :func:`benchmark.scoring.bootstrap_od50`:
an environment keeps all its distances). Scenes that are hard for both cameras then move
both curves together and cancel in the difference, so the interval of ΔAP(d) = AP_A − AP_B
and ΔOD50 = OD50_A − OD50_B is narrower than one from two independent bootstraps
(``paired=False``, kept for comparison and tests). AP per distance of the full sets comes
from :func:`benchmark.scoring.ap_by_distance` (faster-coco-eval); the resamples re-weight
COCO's per-image matches (:func:`benchmark.scoring.bootstrap.weighted_ap`). ± is the
bootstrap SD. The 95 % intervals hold *together*: ΔAP at every distance and the headline
(ΔOD50, or the ΔAP range) are one family, each interval Student's t at the Bonferroni level
times the bootstrap SD scaled for few environments, and ΔOD50's percentile interval is
widened as much (:mod:`benchmark.scoring.simultaneous`), so a camera compared with itself
reseeded is called different in few pairs, not in most (docs/scoring.md).

**Censoring.** When A's or B's OD50 is censored (AP does not cross 0.5 inside the measured
distances: "> 200 m" or "< 25 m"), ΔOD50 in metres is not measured: the verdict rests on the
ΔAP range (area under AP vs distance, :func:`benchmark.scoring.ap_range`, in metres, from the
same paired resamples), called where its interval excludes 0 and the camera with the larger AP
range found enough cars at a distance where its AP is higher (below).

**Minimum sample.** Below :data:`benchmark.scoring.MIN_ENVIRONMENTS` environments per distance
no difference is called: the verdict is the one line "sample too small: ..." and the table
is still printed. Every interval encloses its point (:func:`benchmark.scoring.enclose`).
Per distance each side's miss rate and false positives per image at the working threshold
are reported beside the ΔAP (docs/scoring.md).

**Enough cars behind an AP.** AP is computed from every detection down to score 0.001, so a
camera that sees nothing still gets an AP from a few low-score boxes (0.09 from one box of
score 0.02). A difference at a distance is *called* only when its 95 % interval excludes 0
**and** the camera with the higher AP found at least :func:`cars_needed` of the cars there
(:data:`MIN_FOUND_CARS`, and :data:`MIN_FOUND_FRACTION` of them): a car detection of score ≥
:data:`FOUND_SCORE` overlapping the car's box at IoU ≥ :data:`FOUND_IOU`
(:func:`benchmark.scoring.detection_rates`, ``benchmark score``'s working point). Where
neither camera finds that many, both are *blind* there, and the verdict says so ("both
blind beyond 25 m") instead of calling a difference (docs/scoring.md). The verdict opens with what
the condition physically is (:func:`benchmark.leaderboard.protocols.condition_label`).
"""

from __future__ import annotations

import json
import math
import textwrap
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from benchmark.result_files import ResultsFileError, RunFolder, read_results, read_sweep_record
from benchmark.scoring import (
    FOUND_IOU, FOUND_SCORE, MIN_ENVIRONMENTS, ap_by_distance, ap_range, detection_rates, enclose, format_od50, od50,
    od50_censoring, sample_too_small_text, too_few,
)
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES, _match_tables, percentile_interval, weighted_ap
from benchmark.scoring.simultaneous import family_intervals
from benchmark.suggest import did_you_mean

COMPARE_FORMAT = "metricscenes-compare/1"
MIN_FOUND_CARS = 3
"""Fewest cars the camera with the higher AP must have found at a distance for a difference there to be called."""
MIN_FOUND_FRACTION = 0.2
"""... and at least this fraction of the cars at that distance (10 of 50 on metric-300, 3 of 10 on quick).
A car is found at the working threshold, :data:`benchmark.scoring.FOUND_SCORE` and ``FOUND_IOU``."""


def cars_needed(n_cars: int) -> int:
    """Found cars needed behind an AP at a distance holding ``n_cars`` cars:
    max(:data:`MIN_FOUND_CARS`, ⌈:data:`MIN_FOUND_FRACTION` × n_cars⌉)."""
    return max(MIN_FOUND_CARS, math.ceil(MIN_FOUND_FRACTION * n_cars - 1e-9))


def blind_below(n_cars: int) -> int:
    """A camera that found fewer than this many of ``n_cars`` cars is blind there:
    :func:`cars_needed`, but never more than half the cars (with two cars per distance, one
    found car is not blindness, though no difference can be called on it)."""
    return min(cars_needed(n_cars), max(1, math.ceil(n_cars / 2)))


def working_rows(side: "Side") -> dict[float, dict]:
    """Per distance: :func:`benchmark.scoring.detection_rates` of one run at the working threshold."""
    return {float(r["distance_m"]): r for r in detection_rates(side.groundtruth, side.detections)}


class CompareError(ValueError):
    """The two runs cannot be compared (different collections or environments, not a run)."""


@dataclass(frozen=True)
class Side(RunFolder):
    """One side of a comparison: a run folder's results, ground truth and detections."""

    groundtruth: dict
    detections: list
    name: str | None = None  # a leaderboard submission's name (a reference side), shown as its label

    @property
    def manifest_sha256(self) -> str:
        return self.results.collection.manifest_sha256

    @property
    def environments(self) -> set:
        return {im["environment_id"] for im in self.groundtruth["images"]}

    @property
    def scenes(self) -> set:
        return {(im["environment_id"], float(im["distance_m"])) for im in self.groundtruth["images"]}

    @property
    def environments_per_distance(self) -> int:
        """The fewest environments at any one distance (what the minimum sample is counted in)."""
        per: dict[float, set] = {}
        for env, distance in self.scenes:
            per.setdefault(distance, set()).add(env)
        return min((len(v) for v in per.values()), default=0)


def resolve_run(path: str | Path, camera: str | None = None, condition: str = "day") -> Path:
    """The run folder of ``path``: itself if it holds results.json, else a sweep folder's run
    of ``camera`` × ``condition`` (from sweep.json's run list, or ``runs/<camera>-<condition>``)."""
    path = Path(path)
    if (path / "results.json").is_file():
        return path
    if not path.is_dir():
        raise CompareError(f"{path}: no such folder")
    if camera is None:
        raise CompareError(f"{path} is not a run folder (no results.json); for a sweep folder name the camera with --camera")
    meta_path = path / "sweep.json"
    if meta_path.is_file():
        for run in read_sweep_record(meta_path).runs:
            if run.camera == camera and run.condition == condition:
                return path / run.path
    candidate = path / "runs" / f"{camera}-{condition}"
    if (candidate / "results.json").is_file():
        return candidate
    held = [p.name for p in sorted((path / "runs").glob("*-*")) if (p / "results.json").is_file()]
    hint = did_you_mean(f"{camera}-{condition}", held)
    raise CompareError(f"{path}: no run of camera {camera!r} in condition {condition!r}"
                       + (f" (runs there: {', '.join(held)}){hint}" if held else ""))


def load_side(folder: str | Path) -> Side:
    folder = Path(folder)
    try:
        return Side(folder, read_results(folder / "results.json"),
                    json.loads((folder / "groundtruth.json").read_text()),
                    json.loads((folder / "detections.json").read_text()))
    except FileNotFoundError as exc:
        raise CompareError(f"{folder}: not a run folder ({Path(exc.filename).name} is missing)") from None
    except ResultsFileError as exc:  # already one line naming the file
        raise CompareError(str(exc)) from None
    except json.JSONDecodeError as exc:
        raise CompareError(f"{folder}: unreadable JSON ({exc})") from None


def submission_path(reference: str | Path, leaderboard_dir: str | Path = "leaderboard") -> Path:
    """The submission file of ``reference``: a path to a ``.json``, or a name on the leaderboard
    (``leaderboard_dir/submissions/<name>.json``)."""
    reference = str(reference)
    if reference.endswith(".json") or "/" in reference or "\\" in reference:
        return Path(reference)
    return Path(leaderboard_dir) / "submissions" / f"{reference}.json"


def load_reference(reference: str | Path, condition: str, leaderboard_dir: str | Path = "leaderboard") -> Side:
    """One condition of a leaderboard submission as a comparison side, from the detections and
    ground truth it ships (checksummed: :mod:`benchmark.leaderboard.detections`); refused in one
    line where it has no such condition or ships no detections (made before they shipped)."""
    from benchmark.leaderboard.detections import pack_path, read_pack
    from benchmark.leaderboard.schema import SubmissionError
    from benchmark.leaderboard.validate import read_submission_file
    from benchmark.result_files import CameraRecord, CollectionRecord, RunResults

    path = submission_path(reference, leaderboard_dir)
    if not path.is_file():
        held = sorted(p.stem for p in path.parent.glob("*.json")) if path.parent.is_dir() else []
        raise CompareError(f"--reference {reference}: no such submission ({path}){did_you_mean(path.stem, held)}")
    try:
        data = read_submission_file(path)
        if not isinstance(data, dict) or not isinstance(data.get("conditions"), dict):
            raise SubmissionError(f"{path.name}: not a submission")
        cond = data["conditions"].get(condition)
        if not isinstance(cond, dict):
            raise CompareError(f"{path.stem} has no condition {condition!r} (it has: {', '.join(sorted(data['conditions']))})")
        digest = cond.get("shipped_detections_sha256")
        if digest is None:
            raise CompareError(f"{path.stem} carries no detections (made before detections shipped): it cannot be paired "
                               "by scene; `benchmark report RUN --references PROTOCOL` draws a run over the references' AP")
        body = read_pack(pack_path(path, condition), expected_sha256=digest,
                         source=f"{path.stem}.detections/{condition}.json.gz")
        results = RunResults(camera=CameraRecord(name=data["camera"]["name"]), condition=condition,
                             collection=CollectionRecord(**{k: data["collection"][k] for k in ("name", "protocol", "manifest_sha256")}),
                             scoring_backend=data["scoring"]["backend"])
    except CompareError:
        raise
    except SubmissionError as exc:
        raise CompareError(str(exc)) from None
    except (KeyError, TypeError, ValueError) as exc:
        raise CompareError(f"{path.name}: not a submission ({type(exc).__name__}: {exc})".splitlines()[0]) from None
    return Side(path, results, body["groundtruth"], body["detections"], name=data["name"])


def check_comparable(a: Side, b: Side) -> None:
    """Raise :class:`CompareError` (one line) unless A and B share collection and scenes."""
    if not a.manifest_sha256 or a.manifest_sha256 != b.manifest_sha256:
        raise CompareError(f"cannot compare: {a.folder} and {b.folder} come from different collections "
                           f"(manifest sha256 {str(a.manifest_sha256)[:12]} vs {str(b.manifest_sha256)[:12]})")
    if a.environments != b.environments:
        raise CompareError(f"cannot compare: {a.folder} and {b.folder} hold different environments "
                           f"({len(a.environments)} vs {len(b.environments)}, {len(a.environments & b.environments)} shared)")
    if a.scenes != b.scenes:
        raise CompareError(f"cannot compare: {a.folder} and {b.folder} hold different scenes (environment × distance)")


def _label(side: Side, other: Side) -> str:
    if side.name is not None:
        return side.name
    if side.camera != other.camera:
        return side.camera
    if side.condition != other.condition:
        return f"{side.camera} ({side.condition})"
    return f"{side.camera} ({side.folder.name})" if side.folder.name != other.folder.name else str(side.folder)


def compare_runs(
    a: Side,
    b: Side,
    *,
    n_resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = 0,
    confidence_level: float = 0.95,
    paired: bool = True,
    category_id: int = 3,
) -> dict:
    """Paired bootstrap of ΔAP per distance, ΔOD50 and ΔAP range (A − B); see the module docstring.

    Returns a JSON-able dict: labels, per-distance AP of each and ΔAP with SD and interval (and
    each side's cars found, miss rate and false positives per image), OD50 and AP range of each
    (with censoring), ΔOD50 with SD and interval (None when censored), ΔAP range with SD,
    interval and whether it is called, the minimum sample, the verdict line, and the bootstrap
    settings.
    """
    check_comparable(a, b)
    if n_resamples < 2:
        raise ValueError(f"n_resamples must be >= 2, got {n_resamples}")
    envs = sorted(a.environments, key=str)
    if len(envs) < 2:
        raise CompareError(f"cannot compare: a bootstrap needs two or more environments, got {len(envs)}")
    env_index = {e: k for k, e in enumerate(envs)}
    backend = a.results.scoring_backend
    sides = {}
    for key, side in (("a", a), ("b", b)):
        rows = ap_by_distance(side.groundtruth, side.detections, backend=backend, category_id=category_id)
        dist = [r["distance_m"] for r in rows]
        ap = [r["ap"] for r in rows]
        censored, bound = od50_censoring(dist, ap)
        sides[key] = {"rows": rows, "distances": dist, "ap": np.asarray(ap, dtype=float), "od50_m": od50(dist, ap),
                      "ap_range_m": ap_range(dist, ap), "censored": censored, "bound_m": bound,
                      "tables": _match_tables(side.groundtruth, side.detections, category_id, env_index)}
    distances = sides["a"]["distances"]
    rng = np.random.default_rng(seed)
    n = len(envs)
    d_ap = np.empty((n_resamples, len(distances)))
    d_od = np.empty(n_resamples)
    d_range = np.empty(n_resamples)
    for k in range(n_resamples):
        draw_a = rng.integers(0, n, n)
        draw_b = draw_a if paired else rng.integers(0, n, n)
        ap_ab = []
        for key, draw in (("a", draw_a), ("b", draw_b)):
            w = np.bincount(draw, minlength=n)
            ap_ab.append(np.array([weighted_ap(sides[key]["tables"][d], w)[0] for d in distances]))
        d_ap[k] = ap_ab[0] - ap_ab[1]
        with np.errstate(invalid="ignore"):
            d_od[k] = od50(distances, ap_ab[0]) - od50(distances, ap_ab[1])
        d_range[k] = ap_range(distances, ap_ab[0]) - ap_range(distances, ap_ab[1])
    per_env = min(a.environments_per_distance, b.environments_per_distance)
    too_small = too_few(per_env)  # no call at all: the rows say what the interval alone would be
    delta_ap = sides["a"]["ap"] - sides["b"]["ap"]
    delta_range = float(sides["a"]["ap_range_m"] - sides["b"]["ap_range_m"])
    family = family_intervals(np.append(delta_ap, delta_range), np.column_stack([d_ap, d_range]), n, confidence_level)
    per_distance = []
    working = {"a": working_rows(a), "b": working_rows(b)}
    empty = {"detected": 0, "n_images": 0, "miss_rate": None, "false_positives_per_image": None}
    for j, dm in enumerate(distances):
        delta = float(delta_ap[j])
        lo, hi = family.interval(j, delta)
        wa, wb = working["a"].get(float(dm), empty), working["b"].get(float(dm), empty)
        found_a, n_cars, found_b = int(wa["detected"]), int(wa["n_images"]), int(wb["detected"])
        needed = cars_needed(n_cars)
        backed = (found_a if delta > 0 else found_b) >= needed  # the higher AP rests on found cars
        per_distance.append({"distance_m": float(dm), "ap_a": float(sides["a"]["ap"][j]), "ap_b": float(sides["b"]["ap"][j]),
                             "delta_ap": delta, "sd": _finite(family.sd[j]),
                             "ci95": [lo, hi], "n_cars": n_cars, "found_a": found_a, "found_b": found_b,
                             "cars_needed": needed, "blind_below": blind_below(n_cars),
                             "resolved": bool((lo > 0 or hi < 0) and backed and not too_small),
                             "blind": bool(max(found_a, found_b) < blind_below(n_cars)),
                             "miss_rate_a": wa["miss_rate"], "miss_rate_b": wb["miss_rate"],
                             "fp_per_image_a": wa["false_positives_per_image"],
                             "fp_per_image_b": wb["false_positives_per_image"]})
    censored = bool(sides["a"]["censored"] or sides["b"]["censored"])
    finite = d_od[np.isfinite(d_od)]
    delta_od = float(sides["a"]["od50_m"] - sides["b"]["od50_m"])
    if censored:
        od_block = {"delta_m": None, "sd_m": None, "ci95_m": [None, None]}
    else:
        sd_od = float(np.std(finite, ddof=1)) if finite.size > 1 else None
        if finite.size == n_resamples:  # the headline's place in the family, as the AP range's
            lo, hi = delta_od - family.multiplier * sd_od, delta_od + family.multiplier * sd_od
        else:  # an infinite tail: its percentile interval, widened as much
            lo, hi = family.stretch(delta_od, *enclose(delta_od, *percentile_interval(d_od[~np.isnan(d_od)],
                                                                                      confidence_level)))
        od_block = {"delta_m": delta_od, "sd_m": sd_od, "ci95_m": [float(lo), float(hi)]}
    range_block = _range_block(delta_range, family.interval(len(distances), delta_range), family.sd[-1], per_distance,
                               too_small)
    out = {
        "format": COMPARE_FORMAT,
        "a": {"label": _label(a, b), "folder": str(a.folder), "camera": a.camera, "condition": a.condition,
              "od50_m": _finite(sides["a"]["od50_m"]), "censored": sides["a"]["censored"], "bound_m": sides["a"]["bound_m"],
              "ap_range_m": sides["a"]["ap_range_m"]},
        "b": {"label": _label(b, a), "folder": str(b.folder), "camera": b.camera, "condition": b.condition,
              "od50_m": _finite(sides["b"]["od50_m"]), "censored": sides["b"]["censored"], "bound_m": sides["b"]["bound_m"],
              "ap_range_m": sides["b"]["ap_range_m"]},
        "collection_manifest_sha256": a.manifest_sha256,
        "n_environments": n,
        "environments_per_distance": per_env,
        "min_environments": MIN_ENVIRONMENTS,
        "sample_too_small": too_small,
        "n_resamples": int(n_resamples),
        "seed": int(seed),
        "confidence_level": confidence_level,
        "paired": paired,
        "family": {"members": len(distances) + 1, "sd_multiplier": family.multiplier},
        "found_rule": {"min_cars": MIN_FOUND_CARS, "min_fraction": MIN_FOUND_FRACTION, "score": FOUND_SCORE,
                       "iou": FOUND_IOU},
        "per_distance": per_distance,
        "delta_od50": od_block,
        "delta_ap_range": range_block,
    }
    out["verdict"] = verdict(out)
    return out


def _range_block(delta: float, interval: tuple[float, float], sd: float, per_distance: list[dict],
                 too_small: bool) -> dict:
    """ΔAP range (m) with its SD and interval (one of the family's); ``resolved`` where the
    interval excludes 0 and the camera with the larger AP range found enough cars
    (:func:`cars_needed`) at a distance where its AP is the higher: an area built from
    low-score boxes alone is not called."""
    lo, hi = interval
    side = "a" if delta > 0 else "b"
    sign = 1.0 if delta > 0 else -1.0
    backed = any(sign * r["delta_ap"] > 0 and r[f"found_{side}"] >= r["cars_needed"] for r in per_distance)
    return {"delta_m": delta, "sd_m": _finite(sd), "ci95_m": [lo, hi], "resolved": bool((lo > 0 or hi < 0) and backed and not too_small)}


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _rate(x: float | None) -> str:
    return "–" if x is None else f"{x:.2f}"


def _suffix(cond_a: str, cond_b: str) -> str:
    """" (label A vs label B)" for two conditions, "" for one (the verdict opens with its label:
    :func:`_condition_prefix`); labels from :func:`benchmark.leaderboard.protocols.condition_label`."""
    from benchmark.leaderboard.protocols import condition_label

    return "" if cond_a == cond_b else f" ({condition_label(cond_a)} vs {condition_label(cond_b)})"


def _condition_prefix(result: dict) -> str:
    """"daylight: " where both runs share a condition (what it physically is), else ""."""
    from benchmark.leaderboard.protocols import condition_label

    cond = result["a"]["condition"]
    return f"{condition_label(cond)}: " if cond and cond == result["b"]["condition"] else ""


def _interval_excludes_zero(row: dict) -> bool:
    return row["ci95"][0] > 0 or row["ci95"][1] < 0


def _resolved(row: dict) -> bool:
    """A difference called at this distance: the interval excludes 0 and the higher AP rests
    on enough found cars (rows without the counts: the interval alone)."""
    return row.get("resolved", _interval_excludes_zero(row))


def blind_from(result: dict) -> float | None:
    """The nearest distance from which both cameras are blind at every measured distance
    (neither found :func:`blind_below` cars), or None."""
    rows = sorted(result["per_distance"], key=lambda r: r["distance_m"])
    start = None
    for row in reversed(rows):
        if not row.get("blind", False):
            break
        start = row["distance_m"]
    return start


def _blind_text(result: dict) -> str:
    """"; both blind beyond 25 m (at every distance beyond it, neither camera found 3
    of the 10 cars ...)", or "" (blind at every distance: :func:`verdict` says it alone)."""
    start = blind_from(result)
    if start is None:
        return ""
    rows = sorted(result["per_distance"], key=lambda r: r["distance_m"])
    before = [r["distance_m"] for r in rows if r["distance_m"] < start]
    row = next(r for r in rows if r["distance_m"] == start)
    return f"; both blind beyond {before[-1]:g} m (at every distance beyond it, {_found_rule_text(result, row)})"


def _found_rule_text(result: dict, row: dict) -> str:
    rule = result.get("found_rule", {"score": FOUND_SCORE, "iou": FOUND_IOU})
    needed = row.get("blind_below", row["cars_needed"])
    how_many = "any" if needed == 1 else str(needed)
    return (f"neither camera found {how_many} of the {row['n_cars']} cars: a car detection of score "
            f">= {rule['score']:g} on the car at IoU >= {rule['iou']:g}")


def _unbacked_text(result: dict) -> str:
    """"; at 150 m the interval excludes 0 but ...: not called" for the distances whose
    interval alone would call a difference that too few found cars carry (blind ones aside:
    the blind clause says it)."""
    rows = [r for r in result["per_distance"]
            if _interval_excludes_zero(r) and not _resolved(r) and not r.get("blind", False)]
    if not rows:
        return ""
    where = ", ".join(format(r["distance_m"], "g") for r in rows)
    return (f"; at {where} m the AP interval excludes 0 but the higher AP rests on fewer than "
            f"{rows[0]['cars_needed']} found cars: not called")


def verdict(result: dict) -> str:
    """The plain-language line: "daylight: A detects cars 18 ± 7 m farther than B (95 %: 5–31 m)",
    "... AP differs at 50 m ...", or "...: both blind beyond 25 m", opening with what the
    condition physically is (see the module docstring)."""
    if result.get("sample_too_small"):
        return sample_too_small_text(result["environments_per_distance"])
    a, b = result["a"], result["b"]
    prefix = _condition_prefix(result)
    rows = result["per_distance"]
    if rows and blind_from(result) == min(r["distance_m"] for r in rows):
        first = min(rows, key=lambda r: r["distance_m"])
        last = max(r["distance_m"] for r in rows)
        return (f"{prefix}{a['label']} and {b['label']} are both blind at every measured distance "
                f"({first['distance_m']:g} to {last:g} m: {_found_rule_text(result, first)}): no difference is called")
    return prefix + _od50_verdict(result) + _unbacked_text(result) + _blind_text(result) + _too_few_text(result)


def _too_few_text(result: dict) -> str:
    """"; with 2 cars per distance no difference at a distance can be called (3 found cars
    needed)" where no distance holds enough cars for the rule, else ""."""
    rows = result["per_distance"]
    if not rows or any(r.get("n_cars", math.inf) >= r.get("cars_needed", 0) for r in rows):
        return ""
    return (f"; with {max(r['n_cars'] for r in rows)} cars per distance no difference at a distance can be called "
            f"({rows[0]['cars_needed']} found cars needed)")


def _od50_verdict(result: dict) -> str:
    a, b, od = result["a"], result["b"], result["delta_od50"]
    suffix = _suffix(a["condition"], b["condition"])
    pct = f"{100 * result['confidence_level']:g} %"
    if od["delta_m"] is None:
        resolved = [r for r in result["per_distance"] if _resolved(r)]
        od_a = format_od50(a["od50_m"], a["censored"], a["bound_m"])
        od_b = format_od50(b["od50_m"], b["censored"], b["bound_m"])
        where = ", ".join(format(r["distance_m"], "g") for r in resolved)
        tail = (f"AP differs at {where} m"
                if resolved else "no AP difference resolved at any distance")
        if result.get("delta_ap_range") is not None:
            return _range_verdict(result, od_a, od_b, suffix, tail, pct)
        for first, second in ((a, b), (b, a)):  # a lower bound beats a measured value below it
            if first["censored"] == ">" and not second["censored"] and second["od50_m"] is not None:
                gap = first["bound_m"] - second["od50_m"]
                return (f"{first['label']} detects cars farther than {second['label']}{suffix}, by at least "
                        f"{gap:.0f} m (OD50 {format_od50(None, '>', first['bound_m'])} vs {second['od50_m']:.1f} m; "
                        f"a bound, not a measured difference); {tail} ({pct})")
        return (f"OD50 of {a['label']} is {od_a} and of {b['label']} {od_b}{suffix}: outside the measured distances, "
                f"ΔOD50 is not measured; {tail} ({pct})")
    d, sd, (lo, hi) = od["delta_m"], od["sd_m"] or 0.0, od["ci95_m"]
    if not (lo > 0 or hi < 0):
        return (f"no difference resolved between {a['label']} and {b['label']}{suffix}: "
                f"ΔOD50 = {d:+.0f} ± {sd:.0f} m ({pct}: {lo:.0f} to {hi:.0f} m)")
    word, first, second = ("farther", a, b) if d > 0 else ("farther", b, a)
    if d < 0:
        lo, hi = -hi, -lo
    return (f"{first['label']} detects cars {abs(d):.0f} ± {sd:.0f} m {word} than {second['label']}{suffix} "
            f"({pct}: {lo:.0f}–{hi:.0f} m)")


def _range_verdict(result: dict, od_a: str, od_b: str, when: str, tail: str, pct: str) -> str:
    """The verdict where ΔOD50 is censored: on the ΔAP range (docs/scoring.md, "AP range")."""
    a, b, rng = result["a"], result["b"], result["delta_ap_range"]
    d, sd, (lo, hi) = rng["delta_m"], rng["sd_m"] or 0.0, rng["ci95_m"]
    bounds = f"OD50 {od_a} vs {od_b}: outside the measured distances, ΔOD50 is not measured"
    if not rng["resolved"]:
        return (f"no difference resolved between {a['label']} and {b['label']}{when}: ΔAP range = {d:+.0f} ± {sd:.0f} m "
                f"({pct}: {lo:.0f} to {hi:.0f} m; {bounds}); {tail}")
    first, second = (a, b) if d > 0 else (b, a)
    if d < 0:
        lo, hi = -hi, -lo
    return (f"{first['label']} detects cars farther than {second['label']}{when}: AP range {first['ap_range_m']:.0f} vs "
            f"{second['ap_range_m']:.0f} m, {abs(d):.0f} ± {sd:.0f} m more ({pct}: {lo:.0f}–{hi:.0f} m; {bounds}); {tail}")


def plot_compare(result: dict, out: str | Path) -> Path:
    """AP vs distance of both (left) and ΔAP per distance with its interval (right), as PNG."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    rows = result["per_distance"]
    d = np.array([r["distance_m"] for r in rows])
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    ax1.plot(d, [r["ap_a"] for r in rows], "o-", label=result["a"]["label"])
    ax1.plot(d, [r["ap_b"] for r in rows], "s--", label=result["b"]["label"])
    ax1.axhline(0.5, color="grey", lw=0.8, ls=":")
    ax1.set(xlabel="distance (m)", ylabel="AP", title="AP per distance", ylim=(0, 1))
    ax1.legend()
    delta = np.array([r["delta_ap"] for r in rows])
    lo = np.array([r["ci95"][0] for r in rows], dtype=float)
    hi = np.array([r["ci95"][1] for r in rows], dtype=float)
    yerr = np.nan_to_num(np.stack([np.maximum(delta - lo, 0), np.maximum(hi - delta, 0)]))
    ax2.errorbar(d, delta, yerr=yerr, fmt="o", capsize=4)
    ax2.axhline(0.0, color="grey", lw=0.8)
    pct = f"{100 * result['confidence_level']:g} %"
    ax2.set(xlabel="distance (m)", ylabel=f"ΔAP ({result['a']['label']} − {result['b']['label']})",
            title=f"ΔAP, paired bootstrap over {result['n_environments']} environments ({pct}, "
                  f"{result['n_resamples']} resamples)")
    ax2.title.set_fontsize(9)
    fig.suptitle(textwrap.fill(result["verdict"], 150), fontsize=9)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def compare_paths(path_a, path_b=None, *, cameras=(), condition: str = "day", reference: str | Path | None = None,
                  leaderboard_dir: str | Path = "leaderboard", **kwargs) -> dict:
    """Resolve A and B (run or sweep folders; ``cameras``: none, one for both, or one each) and
    compare; or A against ``reference``, a leaderboard submission (name or path) under A's condition."""
    cameras = list(cameras)
    if (path_b is None) == (reference is None):
        raise CompareError("give B (a run or sweep folder) or --reference (a leaderboard submission), not both")
    if len(cameras) > (1 if reference is not None else 2):
        raise CompareError(f"--camera: give one (both sides) or two (A then B), got {len(cameras)}"
                           if reference is None else "--camera: with --reference give one (A's), or none")
    cam_a = cameras[0] if cameras else None
    cam_b = cameras[-1] if cameras else None
    a = load_side(resolve_run(path_a, cam_a, condition))
    b = load_reference(reference, a.condition, leaderboard_dir) if reference is not None else load_side(
        resolve_run(path_b, cam_b, condition))
    return compare_runs(a, b, **kwargs)


def register(app) -> None:
    """Add ``benchmark compare`` to a Typer app."""
    from rich.console import Console
    from rich.table import Table

    from metricscenes.cli_support import fail

    @app.command()
    def compare(
        a: Annotated[Path, typer.Argument(help="run folder, or sweep folder with --camera")],
        b: Annotated[Optional[Path], typer.Argument(help="run folder, or sweep folder with --camera (or --reference)")] = None,
        reference: Annotated[Optional[str], typer.Option(
            help="instead of B: a leaderboard submission (name, or path to its .json) that ships its detections")] = None,
        leaderboard: Annotated[Path, typer.Option("--leaderboard", help="leaderboard folder --reference names are in")] = Path("leaderboard"),
        camera: Annotated[Optional[list[str]], typer.Option(
            help="camera in a sweep folder: once for both sides, twice for A then B")] = None,
        condition: Annotated[str, typer.Option(help="condition of the runs in sweep folders")] = "day",
        out: Annotated[Optional[Path], typer.Option("--out", "-o", help="folder for compare.json and compare.png")] = None,
        resamples: Annotated[int, typer.Option(min=2, help="bootstrap resamples over environments")] = BOOTSTRAP_RESAMPLES,
        seed: Annotated[int, typer.Option(help="bootstrap seed")] = 0,
    ) -> None:
        """Paired bootstrap (same environments) of ΔAP per distance and ΔOD50 of A − B, with a verdict; B is a
        run, or --reference, a leaderboard submission paired scene by scene through the detections it ships."""
        from metricscenes.outputs import OutputError, check_output

        console, err = Console(), Console(stderr=True)
        try:
            if out is not None:  # not into a collection, a run, a sweep or the leaderboard
                check_output(out, "--out")
            with err.status("paired bootstrap"):
                result = compare_paths(a, b, cameras=camera or (), condition=condition, reference=reference,
                                       leaderboard_dir=leaderboard, n_resamples=resamples, seed=seed)
        except (CompareError, OutputError, ValueError, OSError) as exc:
            fail(str(exc).splitlines()[0])
        ra, rb = result["a"], result["b"]
        table = Table(title=f"{ra['label']} − {rb['label']} · paired bootstrap, {result['n_resamples']} resamples "
                            f"over {result['n_environments']} environments")
        for name in ("distance (m)", f"AP {ra['label']}", f"AP {rb['label']}", "ΔAP ± SD", "95 %",
                     f"cars found {ra['label']}", f"cars found {rb['label']}", f"FP/image {ra['label']}",
                     f"FP/image {rb['label']}", "called"):
            table.add_column(name, justify="right")
        for r in result["per_distance"]:
            called = "yes" if r["resolved"] else ("blind" if r["blind"] else "no")
            table.add_row(f"{r['distance_m']:g}", f"{r['ap_a']:.3f}", f"{r['ap_b']:.3f}",
                          f"{r['delta_ap']:+.3f} ± {r['sd'] or 0:.3f}", f"{r['ci95'][0]:+.3f} to {r['ci95'][1]:+.3f}",
                          f"{r['found_a']}/{r['n_cars']}", f"{r['found_b']}/{r['n_cars']}",
                          _rate(r["fp_per_image_a"]), _rate(r["fp_per_image_b"]), called)
        console.print(table)
        rng, od = result["delta_ap_range"], result["delta_od50"]
        delta_od = ("" if od["delta_m"] is None else f", Δ {od['delta_m']:+.1f} ± {od['sd_m'] or 0:.1f} m "
                    f"(95 %: {od['ci95_m'][0]:.1f} to {od['ci95_m'][1]:.1f} m)")
        console.print(f"OD50: {ra['label']} {format_od50(ra['od50_m'], ra['censored'], ra['bound_m'])}, "
                      f"{rb['label']} {format_od50(rb['od50_m'], rb['censored'], rb['bound_m'])}{delta_od}; AP range: "
                      f"{ra['label']} {ra['ap_range_m']:.1f} m, {rb['label']} {rb['ap_range_m']:.1f} m, "
                      f"Δ {rng['delta_m']:+.1f} ± {rng['sd_m'] or 0:.1f} m (95 %: {rng['ci95_m'][0]:.1f} to "
                      f"{rng['ci95_m'][1]:.1f} m)", highlight=False)
        console.print(f"cars found (1 − miss rate) and FP/image (car boxes that do not find the car, per image): at "
                      f"score >= {FOUND_SCORE:g}, IoU >= {FOUND_IOU:g}; a difference is called where the 95 % interval "
                      f"excludes 0, the higher AP rests on at least {MIN_FOUND_CARS} found cars ({MIN_FOUND_FRACTION:.0%} "
                      f"of them where more) and there are at least {MIN_ENVIRONMENTS} environments per distance; "
                      "'blind': neither camera found that many (docs/scoring.md)", highlight=False)
        console.print(result["verdict"], highlight=False)
        if out is not None:
            out.mkdir(parents=True, exist_ok=True)
            (out / "compare.json").write_text(json.dumps(result, indent=1))
            png = plot_compare(result, out / "compare.png")
            console.print(f"wrote {out / 'compare.json'}, {png}", highlight=False)
