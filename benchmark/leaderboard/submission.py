"""Build a submission from a run folder or a sweep folder (``benchmark submit``).

A run folder (``benchmark run``) holds ``results.json``, ``detections.json`` and
``groundtruth.json``; a sweep folder holds run folders under ``runs/``. One submission is
one camera system: every run of one camera (one run per condition), with the same
camera spec, detector, collection and scoring backend. Before anything is written each
run's detections file is checked against its recorded sha256, AP is recomputed from it,
and OD50's bootstrap SD over environments is computed (:func:`benchmark.scoring.bootstrap_od50`)
unless the run already carries it with the same resampling settings. Each condition's
detections and ground truth are packed (:mod:`benchmark.leaderboard.detections`), AP is
recomputed from the pack too, and :func:`write_submission` writes the packs beside the JSON,
so that ``submit --check`` recomputes every AP from what ships.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from datetime import datetime, timezone
from pathlib import Path

from benchmark.result_files import (
    RESULTS_FORMAT, DetectorRecord, Od50CacheKey, ResultsFileError, RunFolder, read_od50_cache, read_results,
)
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES, Od50Bootstrap
from benchmark.leaderboard.detections import pack_path, pack_run, recompute, sha256_bytes, unpack
from benchmark.leaderboard.protocols import load_protocols
from benchmark.leaderboard.schema import SUBMISSION_FORMAT, SubmissionError
from benchmark.leaderboard.validate import (
    MAX_OD50_M, MAX_SUBMISSION_BYTES, SUBMISSIONS, camera_from_dump, canonical_text, check_name, check_not_duplicate,
    validate_submission, verify_detections,
)
from metricscenes.files import sha256_file, write_atomic

N_RESAMPLES = BOOTSTRAP_RESAMPLES  # the one default (benchmark.scoring.bootstrap)


Run = RunFolder  # one run folder and its parsed results.json


class Submission(dict):
    """A built submission: its JSON fields, and ``packs``, the detections files it ships
    ({condition: gzip bytes}; not part of the JSON), which :func:`write_submission` writes beside it."""

    packs: dict[str, bytes]

    def __init__(self, fields: dict, packs: dict[str, bytes]):
        super().__init__(fields)
        self.packs = dict(packs)


def find_runs(results_dir: str | Path) -> list[Run]:
    """The run folder ``results_dir``, or every ``results_dir/runs/*/`` of a sweep (sorted)."""
    root = Path(results_dir)
    if (root / "results.json").is_file():
        folders = [root]
    else:
        folders = sorted(p.parent for p in root.glob("runs/*/results.json"))
    if not folders:
        raise SubmissionError(f"{root}: neither a run folder (results.json) nor a sweep (runs/*/results.json)")
    runs = []
    for folder in folders:
        try:
            results = read_results(folder / "results.json")
        except ResultsFileError as exc:  # one line naming the file
            raise SubmissionError(str(exc)) from None
        except OSError as exc:
            raise SubmissionError(f"{folder / 'results.json'}: cannot read ({type(exc).__name__})") from None
        if results.format != RESULTS_FORMAT:
            raise SubmissionError(f"{folder / 'results.json'}: not a {RESULTS_FORMAT} file")
        if results.subset: raise SubmissionError(f"{folder}: a subset run (--environments/--distances) cannot be submitted; submit a run of the whole collection")  # noqa: E701
        # what a submission is built from, which a results.json may lack (hand-made ones)
        missing = [name for name, value in (("detector", results.detector), ("camera.spec", results.camera.spec),
                                            ("detections_sha256", results.detections_sha256)) if value is None]
        if missing:
            raise SubmissionError(f"{folder / 'results.json'}: no {', '.join(missing)}; a submission needs a run of `benchmark run`")
        runs.append(Run(folder, results))
    return runs


def group_by_camera(runs: list[Run]) -> dict[str, list[Run]]:
    """Runs by camera name, each group sorted by condition; a camera+condition twice is refused."""
    groups: dict[str, list[Run]] = {}
    for run in runs:
        groups.setdefault(run.camera, []).append(run)
    for camera, group in groups.items():
        group.sort(key=lambda r: r.condition)
        conditions = [r.condition for r in group]
        for c in conditions:
            if conditions.count(c) > 1:
                raise SubmissionError(f"camera {camera!r} has {conditions.count(c)} runs under condition {c!r}; keep one")
    return dict(sorted(groups.items()))


def created_at_now() -> str:
    """ISO 8601 UTC, seconds; ``SOURCE_DATE_EPOCH`` (reproducible-builds.org) fixes it."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    now = datetime.fromtimestamp(int(epoch), timezone.utc) if epoch else datetime.now(timezone.utc)
    return now.strftime("%Y-%m-%dT%H:%M:%SZ")


def _none_if_not_finite(x: float) -> float | None:
    return round(float(x), 3) if math.isfinite(x) else None


def _none_if_beyond_reach(x: float) -> float | None:
    """An OD50 spread or interval end as written: None (+inf) where it is infinite or beyond
    :data:`~benchmark.leaderboard.validate.MAX_OD50_M` (resamples of a nearly flat AP curve
    extrapolate to 1e16 m: no distance, and the validator's limit)."""
    return None if not math.isfinite(x) or x > MAX_OD50_M else round(float(x), 3)


def _detector_licence(detector: DetectorRecord) -> str:
    from benchmark.detectors import registry

    for entry in registry().values():
        if entry.sha256 == detector.sha256 or entry.name == detector.name:
            return entry.licence
    return "unknown"


def _mtf50(spec, measure: bool) -> tuple[float | None, str]:
    """The camera's MTF50 by the one policy (:func:`benchmark.measure.mtf.camera_mtf50`): from the
    slanted edge on when ``measure``, else from the published group on; a measured or
    analytic value rounded to 0.1 cy/mm."""
    from benchmark.measure.mtf import camera_mtf50

    value, source = camera_mtf50(spec, "measured" if measure else "published_group")
    return (round(value, 1) if source in ("measured", "analytic") else value), source


def _cached_bootstrap(folder: Path, detections_sha256: str, n_resamples: int, seed: int) -> Od50Bootstrap | None:
    """The bootstrap a sweep stored in ``<run>/od50.json`` (:func:`benchmark.experiments.sweep.run_od50`), if it is for these settings."""
    try:
        stored = read_od50_cache(folder / "od50.json")
    except (OSError, ResultsFileError):
        return None
    key = Od50CacheKey(detections_sha256=detections_sha256, n_resamples=n_resamples, seed=seed)
    return stored.od50 if stored.key == key else None


def condition_entry(run: Run, *, n_resamples: int = N_RESAMPLES, seed: int = 0, packs: dict | None = None) -> dict:
    """One condition of a submission from a run folder: verified AP, OD50, bootstrap SD, and the
    sha256 of its packed detections (:func:`benchmark.leaderboard.detections.pack_run`), whose
    bytes go into ``packs[condition]`` where given."""
    from benchmark.scoring import bootstrap_od50, od50

    res = run.results
    det_path = run.folder / res.detections_file
    gt_path = run.folder / "groundtruth.json"
    for p in (det_path, gt_path):
        if not p.is_file():
            raise SubmissionError(f"{run.folder}: {p.name} is missing (needed to verify AP and bootstrap OD50)")
    if sha256_file(det_path) != res.detections_sha256:
        raise SubmissionError(f"{det_path}: sha256 differs from results.json's detections_sha256 (file changed?)")
    try:
        packed = pack_run(run)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise SubmissionError(f"{run.folder}: cannot pack its detections ({type(exc).__name__}: {exc})".splitlines()[0]) from None
    if packs is not None:
        packs[run.condition] = packed
    entry = {
        "per_distance": [
            {"distance_m": r.distance_m, "ap": r.ap, "ap50": r.ap50, "n_images": r.n_images}
            for r in sorted(res.per_distance, key=lambda r: r.distance_m)
        ],
        "od50_m": None,  # recomputed below from the AP curve, as the validator does
        "seed": res.seed,
        "detections_sha256": res.detections_sha256,
        "shipped_detections_sha256": sha256_bytes(packed),
    }
    entry["od50_m"] = _none_if_not_finite(od50([r["distance_m"] for r in entry["per_distance"]], [r["ap"] for r in entry["per_distance"]]))
    probe = {"collection": res.collection.model_dump(), "scoring": {"backend": res.scoring_backend},
             "conditions": {run.condition: entry}}
    verify_detections(probe, [det_path], gt_path, source=str(run.folder / "results.json"))
    gt = json.loads(gt_path.read_text(encoding="utf-8"))
    boot = _cached_bootstrap(run.folder, res.detections_sha256, n_resamples, seed)
    if boot is None:
        dets = json.loads(det_path.read_text(encoding="utf-8"))
        with warnings.catch_warnings():  # percentiles of a distribution holding +inf OD50s warn; the CI ends become null
            warnings.simplefilter("ignore", RuntimeWarning)
            boot = bootstrap_od50(gt, dets, n_resamples=n_resamples, seed=seed, backend=res.scoring_backend)
    lo, hi = boot.ci95_m
    entry.update({
        "od50_sd_m": _none_if_beyond_reach(boot.sd_m),
        "od50_ci95_m": [_none_if_beyond_reach(lo), _none_if_beyond_reach(hi)],
        "n_environments": len({im["environment_id"] for im in gt["images"]}),
    })  # fmt: skip
    return dict(sorted(entry.items()))


def build_submission(
    runs: list[Run],
    *,
    name: str,
    submitter: str,
    created_at: str | None = None,
    n_resamples: int = N_RESAMPLES,
    seed: int = 0,
    measure_mtf: bool = True,
    notes: str | None = None,
    protocols: dict | None = None,
) -> dict:
    """A submission of one camera system from its runs (one per condition); validated before it is returned."""
    from metricscenes import __version__

    check_name(name)
    protocols = load_protocols() if protocols is None else protocols
    if runs and runs[0].results.collection.protocol in protocols:  # e.g. day@100lux runs of a sweep are not ranked
        runs = [r for r in runs if r.condition in protocols[runs[0].results.collection.protocol].conditions]
    if not runs:
        raise SubmissionError("no runs to submit (none under a condition the protocol ranks)")
    first = runs[0].results
    for run in runs[1:]:
        r = run.results
        for label, key in (("camera spec", lambda x: x.camera.spec_sha256),
                           ("detector", lambda x: (x.detector.sha256, x.detector.input_size)),
                           ("collection", lambda x: x.collection.manifest_sha256),
                           ("scoring backend", lambda x: x.scoring_backend)):  # fmt: skip
            if key(r) != key(first):
                raise SubmissionError(f"{run.folder}: {label} differs from {runs[0].folder}'s; one submission is one camera system")
    spec = camera_from_dump(first.camera.spec, source=f"{runs[0].folder}/results.json camera.spec")
    mtf50, mtf50_source = _mtf50(spec, measure_mtf)
    det = first.detector
    packs: dict[str, bytes] = {}
    submission = {
        "format": SUBMISSION_FORMAT,
        "name": name,
        "submitter": submitter,
        "created_at": created_at or created_at_now(),
        "package_version": __version__,
        "camera": {"name": spec.name, "spec_sha256": spec.sha256(), "spec": spec.model_dump(mode="json"),
                   "mtf50_cy_per_mm": mtf50, "mtf50_source": mtf50_source},
        "isp": spec.isp.model_dump(mode="json"),
        "detector": {"name": det.name, "family": det.family, "sha256": det.sha256, "licence": _detector_licence(det),
                     "input_size": det.input_size, "score_threshold": det.score_threshold,
                     "multi_label": bool(det.multi_label)},
        "collection": {"name": first.collection.name, "protocol": first.collection.protocol,
                       "manifest_sha256": first.collection.manifest_sha256},
        "scoring": {"backend": first.scoring_backend, "category_id": 3,
                    "bootstrap_resamples": n_resamples, "bootstrap_seed": seed},
        "conditions": {run.condition: condition_entry(run, n_resamples=n_resamples, seed=seed, packs=packs) for run in runs},
    }  # fmt: skip
    if notes:
        submission["notes"] = notes
    if first.numerics is not None:  # runs made since v0.1.0a5 say what decided their bytes
        submission["software"] = {"versions": first.numerics["versions"], "isa_class": first.numerics["isa_class"]}
    if spec.sha256() != first.camera.spec_sha256:
        raise SubmissionError(f"{runs[0].folder}/results.json: camera.spec_sha256 does not match its spec")
    validate_submission(submission, protocols=protocols, source=name)
    for cname, data in packs.items():  # what ships gives what is claimed, as --check will find
        recompute(submission, cname, unpack(data, expected_sha256=submission["conditions"][cname]["shipped_detections_sha256"],
                                            source=f"{name}.detections/{cname}.json.gz"), source=name)
    return Submission(submission, packs)


def software_differences(submission: dict) -> list[str]:
    """How this machine differs from the one that made a submission's runs, in what decides
    bytes, as phrases: "made with numpy 1.0.0 (here 2.1.3), scipy ..." and "made on an x86-64
    avx512 machine (here avx2)"; empty where it does not or the submission does not say."""
    from metricscenes.numeric_pins import isa_class, package_versions

    software = submission.get("software")
    if not software:
        return []
    here = package_versions()
    versions = [f"{name} {made} (here {here.get(name)})" for name, made in sorted(software["versions"].items())
                if here.get(name) != made]
    out = [f"made with {', '.join(versions)}"] if versions else []
    if software["isa_class"] != isa_class():
        out.append(f"made on an x86-64 {software['isa_class']} machine (here {isa_class()})")
    return out


def dumps_submission(submission: dict) -> str:
    """Canonical text of a submission: sorted keys, 1-space indent, trailing newline."""
    return canonical_text(submission)


def _packs_of(submission: dict, packs: dict[str, bytes] | None) -> dict[str, bytes]:
    """The detections files of every condition, each matching its ``shipped_detections_sha256``."""
    packs = packs if packs is not None else getattr(submission, "packs", {})
    name = submission.get("name", "submission")
    for cname, cond in sorted(submission["conditions"].items()):
        digest = cond.get("shipped_detections_sha256")
        if digest is None:
            raise SubmissionError(f"{name}: carries no detections: its AP cannot be recomputed (build it with "
                                  "`benchmark submit` from its runs)")
        if cname not in packs or sha256_bytes(packs[cname]) != digest:
            raise SubmissionError(f"{name}: conditions.{cname}: no detections file with its shipped_detections_sha256 "
                                  f"{digest[:12]}... to write (build it with `benchmark submit` from its runs)")
    return {c: packs[c] for c in submission["conditions"]}


def save_submission(submission: dict, folder: str | Path, packs: dict[str, bytes] | None = None) -> Path:
    """Write ``<name>.detections/<condition>.json.gz`` and then ``<name>.json`` into ``folder``,
    each atomically (a JSON never names files not yet there); no validation. ``packs``: the
    detections files, by default the built submission's own."""
    folder = Path(folder)
    path = folder / f"{check_name(submission['name'])}.json"
    text = dumps_submission(submission)
    if len(text.encode("utf-8")) > MAX_SUBMISSION_BYTES:
        raise SubmissionError(f"{submission['name']}: submission over the 5 MB limit")
    for cname, data in sorted(_packs_of(submission, packs).items()):
        write_atomic(pack_path(path, cname), data)
    return write_atomic(path, text)


def write_submission(submission: dict, leaderboard_dir: str | Path = "leaderboard",
                     packs: dict[str, bytes] | None = None) -> Path:
    """Validate against the leaderboard (protocols, duplicates), then write ``submissions/<name>.json``
    and its detections (:func:`save_submission`)."""
    leaderboard_dir = Path(leaderboard_dir)
    validate_submission(submission, protocols=load_protocols(leaderboard_dir), source=submission.get("name", "submission"))
    check_not_duplicate(submission, leaderboard_dir)
    return save_submission(submission, leaderboard_dir / SUBMISSIONS, packs)
