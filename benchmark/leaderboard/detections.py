"""The detections a submission ships, from which every AP it claims is recomputed.

Beside ``submissions/<name>.json`` lies ``submissions/<name>.detections/<condition>.json.gz``, one
per condition: gzip (level 9, mtime 0, no file name: the same content gives the same bytes) of
one JSON object, sorted keys, no spaces::

    {"format": "metricscenes-detections/1", "condition": "day", "manifest_sha256": "...",
     "groundtruth": {"info": {...}, "categories": [car], "images": [...], "annotations": [car boxes]},
     "detections": [{"image_id", "category_id", "bbox", "score"}, ...]}

Only what scoring reads is kept: the car (COCO category 3: :func:`benchmark.scoring.ap_by_distance`,
the bootstrap and the working threshold read no other), detections of score ≥
:data:`benchmark.scoring.AP_SCORE_THRESHOLD` in the run's order (COCO breaks score ties by it),
the ground truth's car boxes and each image's id, scene, environment, distance and size. AP,
AP50, OD50 and ``compare``'s paired bootstrap from a pack are those of the run's full files.
The submission records each file's sha256 (``conditions.<c>.shipped_detections_sha256``).
"""

from __future__ import annotations

import gzip
import hashlib
import io
import json
from pathlib import Path

from benchmark.leaderboard.schema import SubmissionError, loads_strict

AP_TOLERANCE = 1e-6  # a recomputed AP agrees with the claimed one to float rounding
OD50_TOLERANCE_M = 1e-3  # results round OD50 to the millimetre

DETECTIONS_FORMAT = "metricscenes-detections/1"
CAR_CATEGORY_ID = 3
MAX_PACK_BYTES = 16 * 1024 * 1024  # compressed; a metric-300 condition is about 0.5 MB
MAX_UNPACKED_BYTES = 256 * 1024 * 1024  # a gzip bomb stops here
IMAGE_KEYS = ("id", "scene_id", "environment_id", "distance_m", "width", "height")
DETECTION_KEYS = ("image_id", "category_id", "bbox", "score")


def detections_dir(submission_path: str | Path) -> Path:
    """``submissions/<name>.detections/`` of ``submissions/<name>.json``."""
    path = Path(submission_path)
    return path.with_name(f"{path.stem}.detections")


def pack_path(submission_path: str | Path, condition: str) -> Path:
    return detections_dir(submission_path) / f"{condition}.json.gz"


def pack(groundtruth: dict, detections: list[dict], *, condition: str, manifest_sha256: str) -> bytes:
    """The gzip bytes of one condition's pack (see the module docstring); deterministic."""
    from benchmark.scoring import AP_SCORE_THRESHOLD

    body = {
        "format": DETECTIONS_FORMAT,
        "condition": condition,
        "manifest_sha256": manifest_sha256,
        "groundtruth": {
            "info": groundtruth.get("info", {}),
            "categories": [c for c in groundtruth.get("categories", []) if c.get("id") == CAR_CATEGORY_ID],
            "images": [{k: im[k] for k in IMAGE_KEYS if k in im} for im in groundtruth["images"]],
            "annotations": [{k: v for k, v in a.items() if k != "segmentation"} for a in groundtruth["annotations"]
                            if a["category_id"] == CAR_CATEGORY_ID],
        },
        "detections": [{k: d[k] for k in DETECTION_KEYS} for d in detections
                       if d["category_id"] == CAR_CATEGORY_ID and d["score"] >= AP_SCORE_THRESHOLD],
    }
    raw = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=False, allow_nan=False).encode("utf-8")
    out = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", compresslevel=9, fileobj=out, mtime=0) as f:
        f.write(raw)
    return out.getvalue()


def pack_run(run) -> bytes:
    """The pack of a run folder (:class:`benchmark.result_files.RunFolder`): its ground truth and detections."""
    res = run.results
    gt = json.loads((run.folder / "groundtruth.json").read_text(encoding="utf-8"))
    dets = json.loads((run.folder / res.detections_file).read_text(encoding="utf-8"))
    return pack(gt, dets, condition=run.condition, manifest_sha256=res.collection.manifest_sha256)


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def unpack(data: bytes, *, expected_sha256: str, source: str) -> dict:
    """The pack in ``data``, refused in one line unless its sha256 is ``expected_sha256`` and it
    is a pack (gzip of strict JSON, within the size caps, the fields above)."""
    if len(data) > MAX_PACK_BYTES:
        raise SubmissionError(f"{source}: {len(data)} bytes, over the {MAX_PACK_BYTES // (1024 * 1024)} MB limit")
    digest = sha256_bytes(data)
    if digest != expected_sha256:
        raise SubmissionError(f"{source}: sha256 {digest[:12]}... is not the submission's {expected_sha256[:12]}... "
                              "(the file changed)")
    try:
        with gzip.GzipFile(fileobj=io.BytesIO(data)) as f:
            raw = f.read(MAX_UNPACKED_BYTES + 1)
    except (OSError, EOFError) as exc:
        raise SubmissionError(f"{source}: not a gzip file ({type(exc).__name__})") from None
    if len(raw) > MAX_UNPACKED_BYTES:
        raise SubmissionError(f"{source}: unpacks to over {MAX_UNPACKED_BYTES // (1024 * 1024)} MB")
    body = loads_strict(raw, source)
    if not isinstance(body, dict) or body.get("format") != DETECTIONS_FORMAT:
        raise SubmissionError(f"{source}: not a {DETECTIONS_FORMAT} file")
    gt, dets = body.get("groundtruth"), body.get("detections")
    if (not isinstance(gt, dict) or not isinstance(dets, list) or not all(isinstance(d, dict) for d in dets)
            or not all(isinstance(gt.get(k), list) for k in ("images", "annotations", "categories"))):
        raise SubmissionError(f"{source}: a pack holds 'groundtruth' (images, annotations, categories) and a "
                              "'detections' list")
    return body


def read_pack(path: str | Path, *, expected_sha256: str, source: str | None = None) -> dict:
    """:func:`unpack` of a file; a missing or unreadable one is refused in one line."""
    path = Path(path)
    source = source or str(path)
    try:
        size = path.stat().st_size
        if size > MAX_PACK_BYTES:
            raise SubmissionError(f"{source}: {size} bytes, over the {MAX_PACK_BYTES // (1024 * 1024)} MB limit")
        data = path.read_bytes()
    except FileNotFoundError:
        raise SubmissionError(f"{source}: no such file (the submission's detections are missing)") from None
    except OSError as exc:
        raise SubmissionError(f"{source}: cannot read ({type(exc).__name__})") from None
    return unpack(data, expected_sha256=expected_sha256, source=source)


def recompute(data: dict, condition: str, body: dict, *, source: str) -> None:
    """Refuse, in one line naming the field, the claimed and the recomputed value, any AP, AP50,
    image count, OD50 or environment count of ``data``'s ``condition`` that its pack ``body``
    does not give (AP within :data:`AP_TOLERANCE`: float rounding)."""
    import math

    from benchmark.scoring import ap_by_distance, od50

    cond = data["conditions"][condition]
    where = f"{source}: conditions.{condition}"
    if body.get("condition") != condition:
        raise SubmissionError(f"{where}: its pack is of condition {str(body.get('condition'))[:40]!r}")
    if body.get("manifest_sha256") != data["collection"]["manifest_sha256"]:
        raise SubmissionError(f"{where}: its pack is of another collection (manifest {str(body.get('manifest_sha256'))[:12]}...)")
    try:
        rows = ap_by_distance(body["groundtruth"], body["detections"], backend=data["scoring"]["backend"])
    except (ValueError, KeyError, TypeError) as exc:
        raise SubmissionError(f"{where}: its pack cannot be scored ({type(exc).__name__}: {exc})".splitlines()[0]) from None
    got = {float(r["distance_m"]): r for r in rows}
    for claimed in cond["per_distance"]:
        d = float(claimed["distance_m"])
        r = got.get(d)
        if r is None:
            raise SubmissionError(f"{where}.per_distance[{d:g} m]: the pack holds no image at {d:g} m")
        for key in ("n_images", "ap", "ap50"):
            ok = r[key] == claimed[key] if key == "n_images" else abs(float(r[key]) - claimed[key]) <= AP_TOLERANCE
            if not ok:
                shown = (claimed[key], r[key]) if key == "n_images" else (f"{claimed[key]:.6f}", f"{float(r[key]):.6f}")
                raise SubmissionError(f"{where}.per_distance[{d:g} m].{key} is {shown[0]}, but {shown[1]} "
                                      "recomputed from its shipped detections")
    extra = sorted(set(got) - {float(c["distance_m"]) for c in cond["per_distance"]})
    if extra:
        raise SubmissionError(f"{where}: the pack holds images at {extra[0]:g} m, a distance the submission does not report")
    value = od50([r["distance_m"] for r in rows], [r["ap"] for r in rows])
    value = round(value, 3) if math.isfinite(value) else None
    claimed = cond["od50_m"]
    if (value is None) != (claimed is None) or (value is not None and abs(value - claimed) > OD50_TOLERANCE_M):
        raise SubmissionError(f"{where}.od50_m is {claimed}, but {value} recomputed from its shipped detections")
    envs = len({im.get("environment_id") for im in body["groundtruth"]["images"]})
    if envs != cond["n_environments"]:
        raise SubmissionError(f"{where}.n_environments is {cond['n_environments']}, but its shipped detections hold {envs}")
