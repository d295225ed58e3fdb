"""Bootstrap SD and CI of OD50 over environments (DESIGN §4).

Environments are resampled with replacement; each keeps all its distances (the paired
design). A resample repeats some environments, so its COCO form needs fresh image ids
(:func:`resample_environments` builds it; used by the tests as the oracle).

Speed: instead of running COCOeval per resample, the per-image matching is computed once
(pycocotools ``COCOeval.evaluate``: per image and IoU threshold, which detections match),
and each resample only re-accumulates: an environment drawn k times weighs its images' true
and false positives by k in COCO's cumulative precision/recall (``accumulate`` re-written
with weights). Repeated copies of a detection are adjacent in the score order and either
all true or all false positives, so collapsing them changes no interpolated precision;
``tests/test_scoring_bootstrap.py`` checks equality with COCOeval on resampled COCO sets.
The only difference left: exact score ties *between different images* are ordered by the
original image order instead of the resample's.

Resampling and the percentile interval come from ``scipy.stats.bootstrap`` (``percentile``
method; BCa is not used because OD50 can be +inf for a resample). The AP range
(:mod:`benchmark.scoring.ap_range`) is computed from the same resampled AP curves as OD50.

**Point inside its interval.** On few environments the full-sample value can fall outside
the percentile interval of its resamples; every interval reported goes through
:func:`enclose`: [min(lo, point), max(hi, point)] (docs/scoring.md).

**Few environments.** A bootstrap over n environments underestimates a mean's variance by
(n − 1)/n, and a normal quantile ignores that the spread is itself estimated from n values:
both intervals are stretched about their points by
:func:`~benchmark.scoring.simultaneous.few_environments_scale` (Student's
t over the normal quantile, times √(n/(n − 1))), no lower than 0 m (both are distances). The
SDs are the resamples' own.
"""

from __future__ import annotations

import contextlib
import io
from collections import defaultdict
from dataclasses import dataclass

import numpy as np
from scipy import stats

from benchmark.record_base import Censored, JsonFloat, Record
from benchmark.scoring.ap import ALL_AREAS, MAX_DETS, ap_by_distance, images_by_distance
from benchmark.scoring.ap_range import ap_range
from benchmark.scoring.od50 import od50, od50_censoring
from benchmark.scoring.simultaneous import few_environments_scale, stretch

REC_THRS = np.linspace(0.0, 1.00, 101)  # COCO recall thresholds
IOU_THRS = np.linspace(0.5, 0.95, 10)
BOOTSTRAP_RESAMPLES = 1000  # the one default: run report, sweep, leaderboard and compare (printed with results)


class Od50Bootstrap(Record):
    """OD50 with its bootstrap spread over environments (:func:`bootstrap_od50`); the record
    ``od50.json`` caches (:class:`benchmark.result_files.Od50Cache`).

    Caches written before censoring was recorded lack ``censored`` and ``bound_m``; hand-made
    ones may lack the counts; caches written before the AP range lack ``ap_range_*`` (and their
    intervals may not hold the point): ``run_od50`` computes those again.
    """

    od50_m: JsonFloat  # of the full set, m; +inf where AP never falls to 0.5; extrapolated where censored
    sd_m: JsonFloat  # SD (ddof 1) of the finite resampled OD50s, m; NaN with fewer than two
    ci95_m: tuple[JsonFloat, JsonFloat]  # percentile interval (95 % by default), m; an end may be +inf
    n_resamples: int
    n_environments: int | None = None  # the environments resampled (each keeps all its distances)
    n_infinite: int | None = None  # resamples whose OD50 is +inf (they still enter the interval)
    censored: Censored | None = None  # of the full set (benchmark.scoring.od50.od50_censoring)
    bound_m: float | None = None  # the farthest (">") or nearest ("<") measured distance; None when not censored
    ap_range_m: float | None = None  # area under AP vs distance of the full set, m (benchmark.scoring.ap_range)
    ap_range_sd_m: float | None = None  # SD (ddof 1) of the resampled AP ranges, m
    ap_range_ci95_m: tuple[float, float] | None = None  # percentile interval of the AP range, m, enclosing the point
    interval_scale: float | None = None  # both intervals stretched about their points by this (few environments)


def resample_environments(groundtruth: dict, detections: list[dict], environments) -> tuple[dict, list[dict]]:
    """COCO ground truth and detections of a resample (a list of environment ids, repeats allowed).

    Images get fresh ids 1..n in the order of ``environments`` (then by original id), so a
    repeated environment appears as distinct images; annotations and detections follow.
    """
    by_env: dict = defaultdict(list)
    for im in sorted(groundtruth["images"], key=lambda im: im["id"]):
        by_env[im["environment_id"]].append(im)
    anns, dets = defaultdict(list), defaultdict(list)
    for a in groundtruth["annotations"]:
        anns[a["image_id"]].append(a)
    for d in detections:
        dets[d["image_id"]].append(d)
    images, annotations, results = [], [], []
    for env in environments:
        if env not in by_env:
            raise ValueError(f"environment_id {env!r} is not in the ground truth")
        for im in by_env[env]:
            new_id = len(images) + 1
            images.append({**im, "id": new_id, "source_image_id": im["id"]})
            for a in anns[im["id"]]:
                annotations.append({**a, "id": len(annotations) + 1, "image_id": new_id})
            results.extend({**d, "image_id": new_id} for d in dets[im["id"]])
    gt = {**{k: v for k, v in groundtruth.items() if k not in ("images", "annotations")}, "images": images, "annotations": annotations}
    return gt, results


@dataclass
class _DistanceTable:
    """Matches of one distance's detections, sorted by score as COCO accumulate does."""

    img: np.ndarray  # (D,) image index (into the distance's image list) of each detection
    tps: np.ndarray  # (T, D) bool: true positive at each IoU threshold (not ignored)
    fps: np.ndarray  # (T, D) bool: false positive (not ignored)
    npig: np.ndarray  # (n_images,) ground-truth objects that count (not ignored) per image
    env: np.ndarray  # (n_images,) environment index of each image


def _match_tables(groundtruth: dict, detections: list[dict], category_id: int, env_index: dict) -> dict[float, _DistanceTable]:
    from pycocotools.coco import COCO
    from pycocotools.cocoeval import COCOeval

    dets = [d for d in detections if int(d["category_id"]) == category_id]
    images = {int(im["id"]): im for im in groundtruth["images"]}
    T = IOU_THRS.size
    if dets:
        with contextlib.redirect_stdout(io.StringIO()):
            gt = COCO()
            gt.dataset = groundtruth
            gt.createIndex()
            ev = COCOeval(gt, gt.loadRes(dets), iouType="bbox")
            ev.params.areaRng, ev.params.areaRngLbl = [ALL_AREAS], ["all"]
            ev.params.maxDets, ev.params.catIds = list(MAX_DETS), [category_id]
            ev.params.imgIds = sorted(images)
            ev.evaluate()
        per_image = dict(zip(ev.params.imgIds, ev.evalImgs))  # one category, one area range
    else:  # no detections: only the ground-truth counts matter (COCO ignores crowd boxes)
        n_gt = defaultdict(int)
        for a in groundtruth["annotations"]:
            if int(a["category_id"]) == category_id and not a.get("iscrowd", 0):
                n_gt[int(a["image_id"])] += 1
        empty = np.zeros((T, 0))
        per_image = {i: {"gtIgnore": np.zeros(n_gt[i]), "dtScores": [], "dtMatches": empty, "dtIgnore": empty} for i in images}
    tables = {}
    for distance_m, ids in images_by_distance(groundtruth).items():
        ids = sorted(ids)
        scores, img, dtm, dtig = [], [], [], []
        npig = np.zeros(len(ids))
        for k, i in enumerate(ids):
            e = per_image[i]
            if e is None:
                continue
            npig[k] = np.count_nonzero(np.asarray(e["gtIgnore"]) == 0)
            scores.append(np.asarray(e["dtScores"], dtype=np.float64))
            img.append(np.full(len(e["dtScores"]), k))
            dtm.append(np.asarray(e["dtMatches"]).reshape(T, -1))
            dtig.append(np.asarray(e["dtIgnore"]).reshape(T, -1))
        if scores:
            s = np.concatenate(scores)
            order = np.argsort(-s, kind="mergesort")
            m = np.concatenate(dtm, axis=1)[:, order] != 0
            ig = np.concatenate(dtig, axis=1)[:, order] != 0
            im_idx = np.concatenate(img)[order]
        else:
            m = ig = np.zeros((T, 0), dtype=bool)
            im_idx = np.zeros(0, dtype=np.int64)
        env = np.array([env_index[images[i]["environment_id"]] for i in ids])
        tables[distance_m] = _DistanceTable(im_idx, m & ~ig, ~m & ~ig, npig, env)
    return tables


def weighted_ap(table: _DistanceTable, env_weights: np.ndarray) -> tuple[float, float]:
    """(AP@[.5:.95], AP50) of one distance with each environment counted ``env_weights[e]`` times."""
    w_img = env_weights[table.env].astype(np.float64)
    npig = float(np.sum(w_img * table.npig))
    if npig == 0:
        return float("nan"), float("nan")
    wd = w_img[table.img]
    keep = wd > 0
    wd = wd[keep]
    if wd.size == 0:
        return 0.0, 0.0
    tp = np.cumsum(table.tps[:, keep] * wd, axis=1)
    fp = np.cumsum(table.fps[:, keep] * wd, axis=1)
    rc = tp / npig
    pr = tp / (fp + tp + np.spacing(1))
    pr = np.maximum.accumulate(pr[:, ::-1], axis=1)[:, ::-1]  # COCO's precision envelope
    q = np.zeros((tp.shape[0], REC_THRS.size))
    for t in range(tp.shape[0]):
        idx = np.searchsorted(rc[t], REC_THRS, side="left")
        ok = idx < rc.shape[1]
        q[t, ok] = pr[t, idx[ok]]
    return float(q.mean()), float(q[0].mean())


def bootstrap_od50(
    groundtruth: dict,
    detections: list[dict],
    *,
    n_resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = 0,
    backend: str = "faster-coco-eval",
    category_id: int = 3,
    confidence_level: float = 0.95,
) -> Od50Bootstrap:
    """OD50 and AP range (from the full set, ``backend``) with their bootstrap SD and percentile
    CI over environments, from the same resamples.

    Returns an :class:`Od50Bootstrap`: ``od50_m``, ``sd_m``,
    ``ci95_m`` (lo, hi), ``n_resamples``, ``n_environments``, ``n_infinite``, ``censored``
    and ``bound_m`` ("", ">" or "<" of the full set and its bound, :func:`od50_censoring`),
    ``ap_range_m``, ``ap_range_sd_m``, ``ap_range_ci95_m``;
    ``sd_m`` is the SD (ddof 1) of the finite resampled OD50s, ``n_infinite`` counts
    resamples whose AP never falls to 0.5 (OD50 = inf; they still enter the CI). Both
    intervals enclose their point (:func:`enclose`).
    """
    if n_resamples < 2:
        raise ValueError(f"n_resamples must be >= 2, got {n_resamples}")
    envs = sorted({im["environment_id"] for im in groundtruth["images"]}, key=str)
    if len(envs) < 2:
        raise ValueError(f"bootstrap needs two or more environments, got {len(envs)}")
    env_index = {e: k for k, e in enumerate(envs)}
    rows = ap_by_distance(groundtruth, detections, backend=backend, category_id=category_id)
    curve = ([r["distance_m"] for r in rows], [r["ap"] for r in rows])
    point, range_point = od50(*curve), ap_range(*curve)
    censored, bound_m = od50_censoring(*curve)
    tables = _match_tables(groundtruth, detections, category_id, env_index)
    distances = list(tables)

    def statistic(sample: np.ndarray) -> np.ndarray:
        w = np.bincount(sample.astype(np.int64), minlength=len(envs))
        ap = [weighted_ap(tables[d], w)[0] for d in distances]
        return np.array([od50(distances, ap), ap_range(distances, ap)])

    res = stats.bootstrap(
        (np.arange(len(envs)),),
        statistic,
        n_resamples=n_resamples,
        vectorized=False,
        method="percentile",
        confidence_level=confidence_level,
        rng=np.random.default_rng(seed),
    )
    dist, ranges = np.asarray(res.bootstrap_distribution, dtype=np.float64)
    finite = dist[np.isfinite(dist)]
    scale = few_environments_scale(len(envs), confidence_level)
    lo, hi = stretch(point, *enclose(point, *percentile_interval(dist, confidence_level)), scale, floor=0.0)
    return Od50Bootstrap(
        od50_m=float(point),
        sd_m=float(np.std(finite, ddof=1)) if finite.size > 1 else float("nan"),
        ci95_m=(float(lo), float(hi)),
        n_resamples=int(n_resamples),
        n_environments=len(envs),
        n_infinite=int(dist.size - finite.size),
        censored=censored,
        bound_m=bound_m,
        ap_range_m=float(range_point),
        ap_range_sd_m=float(np.std(ranges, ddof=1)),
        ap_range_ci95_m=stretch(range_point, *enclose(range_point, *percentile_interval(ranges, confidence_level)), scale,
                                floor=0.0),
        interval_scale=scale,
    )


def enclose(point: float, lo: float, hi: float) -> tuple[float, float]:
    """[min(lo, point), max(hi, point)]: the interval reported, which always holds its point. On
    few environments the percentile interval can miss the full-sample value (its resamples
    cluster on one side); the interval is widened to it rather than shown beside it. NaN
    ends or point: unchanged."""
    if point != point or lo != lo or hi != hi:
        return float(lo), float(hi)
    return float(min(lo, point)), float(max(hi, point))


def percentile_interval(values: np.ndarray, confidence_level: float = 0.95) -> tuple[float, float]:
    """Percentile interval of a bootstrap distribution that may hold +inf (OD50 beyond
    reach). The ends are order statistics rounded outwards, not interpolated, so an
    infinite neighbour gives inf rather than inf - inf = NaN."""
    values = np.asarray(values, dtype=np.float64)
    if values.size == 0:
        return (float("nan"), float("nan"))
    tail = round(50.0 * (1.0 - confidence_level), 9)  # 50 * (1 - 0.9) is 4.999...; keep it 5
    return (float(np.percentile(values, tail, method="lower")),
            float(np.percentile(values, 100.0 - tail, method="higher")))
