"""Validation of a submission: file, JSON, schema, then what the schema cannot say.

Each refusal is a :class:`SubmissionError` with a one-line reason. The checks beyond the
schema: no string holds a control character, line break, lone surrogate or invisible
formatting character (a right-to-left override, a zero-width space) and no number is
infinite (:func:`benchmark.leaderboard.schema.check_values`); no name is blank or padded
with spaces; ``created_at`` is a real date, not in the future nor before the protocol's
paper (2023); ``package_version`` is a version no newer than the checker's; ``software``
names byte-deciding packages with their versions; the camera spec's sha256
matches its content, and a measured or analytic MTF50 is the one its spec gives; the
detector is what ``benchmark run`` records (a registry model's name, sha256, family and
licence together, an input-size policy, AP's score threshold 0.001, multi-label); the
protocol and manifest hash are accepted (:mod:`benchmark.leaderboard.protocols`) and the
collection has the protocol's collection name; every
condition has exactly the protocol's distances, one image per environment at each, the
protocol's number of environments and its own detections file, and the required conditions
are there; AP never exceeds AP50; OD50 follows from the AP curve
(:func:`benchmark.scoring.od50`) and lies inside its ordered 95 % interval, whose SD is 0
only if it has no width, none of them above :data:`MAX_OD50_M`; the name is new on the leaderboard, and so are the system (camera
spec, detector, collection: a reproduction is not a second row) and its detections; every
condition ships its detections beside the file (:mod:`benchmark.leaderboard.detections`), whose
sha256 matches and from which AP, AP50, OD50 and the counts are recomputed
(:func:`check_shipped`), unless the protocol pins the file as made before detections shipped
(accepted with a :class:`NoDetectionsWarning`); and, given a run's detections file and ground
truth, AP recomputed with :func:`benchmark.scoring.ap_by_distance` equals the claimed AP within 1e-6.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import warnings
from datetime import datetime, timedelta, timezone
from pathlib import Path

from benchmark.leaderboard.detections import AP_TOLERANCE, OD50_TOLERANCE_M
from benchmark.leaderboard.protocols import Protocol, load_protocols
from benchmark.leaderboard.schema import SubmissionError, check_schema, check_values, loads_strict
from metricscenes.files import sha256_file

MAX_SUBMISSION_BYTES = 5 * 1024 * 1024
MTF50_TOLERANCE = 0.1  # cy/mm: submissions round MTF50 to 0.1 cy/mm (one step of slack: another machine's rounding)
# Free-text fields that name something: not blank, not padded with spaces (a row that looks like another's)
NAMED_FIELDS = (("submitter",), ("camera", "name"), ("detector", "name"), ("detector", "family"),
                ("detector", "licence"), ("collection", "name"), ("package_version",))
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,79}")
CLOCK_TOLERANCE = timedelta(days=1)  # created_at may be this far ahead of the checker's clock
EARLIEST_CREATED_AT = datetime(2023, 1, 1, tzinfo=timezone.utc)  # the protocol's paper (Liu et al., EI 2023)
MAX_OD50_M = 1e9  # beyond any extrapolated OD50 of a real AP curve (the committed ones reach 3e5 m)
SUBMISSIONS = "submissions"


class NoDetectionsWarning(UserWarning):
    """A submission made before detections shipped, accepted without them: its AP is not recomputed."""


def canonical_text(data: dict) -> str:
    """Canonical text of a submission: sorted keys, 1-space indent, trailing newline (how files are written)."""
    return json.dumps(data, indent=1, sort_keys=True, ensure_ascii=False, allow_nan=False) + "\n"


def canonical_sha256(data: dict) -> str:
    """sha256 of a submission's canonical text: what ``made_before_detections`` pins, so that an
    edited file is no longer the one accepted."""
    return hashlib.sha256(canonical_text(data).encode("utf-8")).hexdigest()


def check_name(name: str) -> str:
    """``name`` if it is a safe file stem (letters, digits, ``._-``; no separators, no leading dot)."""
    if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):  # fullmatch: "$" would accept a trailing newline
        raise SubmissionError(
            f"unsafe submission name {name!r}: use 1-80 letters, digits, '.', '_' or '-', starting with a letter or digit"
        )
    return name


def read_submission_file(path: str | Path) -> dict:
    """Read a submission file: safe ``<name>.json`` file name, at most 5 MB, strict JSON, an object."""
    path = Path(path)
    if path.suffix != ".json":
        raise SubmissionError(f"{path.name}: a submission file name must end in .json")
    check_name(path.stem)
    if not path.is_file():
        raise SubmissionError(f"{path}: no such file")
    size = path.stat().st_size
    if size > MAX_SUBMISSION_BYTES:
        raise SubmissionError(f"{path.name}: {size} bytes, over the {MAX_SUBMISSION_BYTES // (1024 * 1024)} MB limit")
    data = loads_strict(path.read_bytes(), path.name)
    if isinstance(data, dict) and isinstance(data.get("name"), str) and data["name"] != path.stem:
        raise SubmissionError(f"{path.name}: file name must be <name>.json, and name is {data['name']!r}")
    return data


def _finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _without_computed(model, data):
    """A ``model_dump`` with the computed fields (e.g. ``sensor.width_px``) taken out, for re-validation."""
    from pydantic import BaseModel

    if not isinstance(data, dict):
        return data
    out = {k: v for k, v in data.items() if k not in model.model_computed_fields}
    for key, field in model.model_fields.items():
        ann = field.annotation
        if key in out and isinstance(ann, type) and issubclass(ann, BaseModel):
            out[key] = _without_computed(ann, out[key])
    return out


def _first_difference(given, resolved, where: str = "") -> str | None:
    """Path of the first value of ``given`` that ``resolved`` does not repeat (keys only in ``resolved`` are fine)."""
    if isinstance(given, dict) and isinstance(resolved, dict):
        for key in sorted(given):
            found = _first_difference(given[key], resolved.get(key), f"{where}.{key}" if where else key)
            if found:
                return found
        return None
    return None if given == resolved else where


def camera_from_dump(spec: dict, source: str = "camera.spec"):
    """The :class:`CameraSpec` of a resolved dump (as in results.json).

    Every value of the dump, derived ones (``sensor.width_px``) included, must be what the
    spec resolves to; fields the dump lacks take the current defaults (a spec written
    before a field was added still reads).
    """
    from benchmark.camera import CameraSpec, camera_from_dict

    try:
        camera = camera_from_dict(_without_computed(CameraSpec, spec), source=source)
    except ValueError as exc:
        raise SubmissionError(str(exc).splitlines()[0]) from None
    where = _first_difference(spec, camera.model_dump(mode="json"))
    if where:
        raise SubmissionError(f"{source}: {where} is not what the spec resolves to (derived values must not be edited)")
    return camera


def _check_camera(data: dict, source: str) -> None:
    cam = data["camera"]
    # the hash of the content as given (CameraSpec.canonical_json's formula), then that content must be a resolved spec
    canonical = json.dumps(cam["spec"], sort_keys=True, separators=(",", ":"))
    actual = hashlib.sha256(canonical.encode("utf-8")).hexdigest()
    if actual != cam["spec_sha256"]:
        raise SubmissionError(
            f"{source}: camera.spec_sha256 {cam['spec_sha256'][:12]}... does not match the spec's content ({actual[:12]}...)"
        )
    try:
        spec = camera_from_dump(cam["spec"])
    except SubmissionError as exc:
        raise SubmissionError(f"{source}: {exc}") from None
    if cam["name"] != spec.name:
        raise SubmissionError(f"{source}: camera.name {cam['name']!r} differs from camera.spec.name {spec.name!r}")
    if data["isp"] != spec.isp.model_dump(mode="json"):
        raise SubmissionError(f"{source}: isp differs from camera.spec.isp (it must be a copy of it)")
    value, kind = cam["mtf50_cy_per_mm"], cam["mtf50_source"]
    if kind == "none" and value is not None:
        raise SubmissionError(f"{source}: camera.mtf50_cy_per_mm must be null when mtf50_source is 'none'")
    if kind == "none" and spec.mtf50_group_cy_per_mm is not None:
        raise SubmissionError(f"{source}: camera.mtf50_source is 'none', but the spec has a published MTF50 group "
                              f"({spec.mtf50_group_cy_per_mm:g} cy/mm)")
    if kind == "published_group" and value != spec.mtf50_group_cy_per_mm:
        raise SubmissionError(f"{source}: camera.mtf50_cy_per_mm {value} is not the spec's published group {spec.mtf50_group_cy_per_mm}")
    if kind in ("measured", "analytic") and value is None:
        raise SubmissionError(f"{source}: camera.mtf50_cy_per_mm is null but mtf50_source is {kind!r}")
    if kind in ("measured", "analytic"):
        expected, got = _spec_mtf50(spec, kind)
        if got != kind or abs(expected - value) > MTF50_TOLERANCE:
            raise SubmissionError(f"{source}: camera.mtf50_cy_per_mm {value} ({kind}) is not the camera's: its spec "
                                  f"gives {expected:.1f} cy/mm ({got})")


_MTF50_CACHE: dict[tuple[str, str], tuple[float, str]] = {}


def _spec_mtf50(spec, kind: str) -> tuple[float, str]:
    """MTF50 (cy/mm) of a camera spec by the one policy, from ``kind`` on (measured: the
    simulated slanted edge, 0.1 s), and the source that gave it; cached per spec sha256."""
    from benchmark.measure.mtf import camera_mtf50

    key = (spec.sha256(), kind)
    if key not in _MTF50_CACHE:
        value, got = camera_mtf50(spec, kind)
        _MTF50_CACHE[key] = (float("nan") if value is None else float(value), got)
    return _MTF50_CACHE[key]


def _check_package_version(text: str, source: str) -> None:
    """``package_version`` is a PEP 440 version no newer than the checker's own metricscenes
    (a submission is made by a released version or this one, and the leaderboard is checked
    with the newest)."""
    from packaging.version import InvalidVersion, Version

    from metricscenes import __version__

    try:
        made = Version(text)
    except InvalidVersion:
        raise SubmissionError(f"{source}: package_version {text!r} is not a version (PEP 440, e.g. {__version__})") from None
    if made > Version(__version__):
        raise SubmissionError(f"{source}: package_version {text} is newer than this checker's metricscenes "
                              f"{__version__}: no such version made it (or check it with that version)")


def _check_software(software: dict, source: str) -> None:
    """``software.versions`` names byte-deciding packages (:data:`metricscenes.numeric_pins.BYTE_DECIDING_PACKAGES`),
    one or more, each with the version installed where the runs were made (a run needs every one of them)."""
    from packaging.version import InvalidVersion, Version

    from metricscenes.numeric_pins import BYTE_DECIDING_PACKAGES

    versions = software["versions"]
    if not versions:
        raise SubmissionError(f"{source}: software.versions is empty (it names the versions that made the runs' bytes)")
    for name, made in versions.items():
        if name not in BYTE_DECIDING_PACKAGES:
            raise SubmissionError(f"{source}: software.versions names {name[:40]!r}{'...' if len(name) > 40 else ''}, "
                                  f"not a package that decides the bytes ({', '.join(BYTE_DECIDING_PACKAGES)})")
        try:
            Version(made)
        except (InvalidVersion, TypeError):
            raise SubmissionError(f"{source}: software.versions.{name} is {made!r}, not a version (each package "
                                  "is installed where a run is made)") from None


def _check_named_fields(data: dict, source: str) -> None:
    """No name is blank or starts or ends with white space ("cam12 " would pass for cam12)."""
    for path in NAMED_FIELDS:
        value = data
        for key in path:
            value = value.get(key) if isinstance(value, dict) else None
        if isinstance(value, str) and (not value.strip() or value != value.strip()):
            raise SubmissionError(f"{source}: {'.'.join(path)} {value!r} is blank or padded with white space")


def _check_detector(data: dict, source: str) -> None:
    """The detector as ``benchmark run`` records it: a registry model's name, sha256,
    family and licence go together (a registry name with another file, or a registry file
    under another name, is refused); its family is a known one, its input size a policy;
    AP is scored at threshold 0.001 with multi-label boxes."""
    from benchmark.detectors import registry
    from benchmark.detectors.onnx_detector import FAMILIES
    from benchmark.detectors.policy import parse_input_size
    from benchmark.scoring.ap import AP_SCORE_THRESHOLD

    det = data["detector"]
    models = registry()
    by_sha = {m.sha256: m for m in models.values()}
    entry = models.get(det["name"])
    if entry is not None and det["sha256"] != entry.sha256:
        raise SubmissionError(f"{source}: detector.sha256 {det['sha256'][:12]}... is not the sha256 of registry model "
                              f"{entry.name!r} ({entry.sha256[:12]}...)")
    entry = entry or by_sha.get(det["sha256"])
    if entry is not None and det["name"] != entry.name:
        raise SubmissionError(f"{source}: detector.sha256 {det['sha256'][:12]}... is registry model {entry.name!r}, "
                              f"but detector.name is {det['name']!r}")
    if entry is not None:
        for field in ("family", "licence"):
            if det[field] != getattr(entry, field):
                raise SubmissionError(f"{source}: detector.{field} {det[field]!r} is not registry model "
                                      f"{entry.name!r}'s ({getattr(entry, field)!r})")
    if det["family"] not in FAMILIES:
        raise SubmissionError(f"{source}: detector.family {det['family']!r} is not a known family "
                              f"({', '.join(sorted(FAMILIES))})")
    try:
        parse_input_size(det["input_size"])
    except ValueError as exc:
        raise SubmissionError(f"{source}: detector.{exc}") from None
    if det["score_threshold"] != AP_SCORE_THRESHOLD:
        raise SubmissionError(f"{source}: detector.score_threshold {det['score_threshold']} is not AP's "
                              f"{AP_SCORE_THRESHOLD} (`benchmark run` keeps every detection down to it)")
    if det.get("multi_label") is False:
        raise SubmissionError(f"{source}: detector.multi_label is false; `benchmark run` scores AP with multi-label "
                              "boxes")


def _check_condition(cname: str, cond: dict, protocol: Protocol, source: str) -> None:
    from benchmark.scoring import od50

    where = f"{source}: conditions.{cname}.per_distance"
    seen = [float(r["distance_m"]) for r in cond["per_distance"]]
    for d in seen:
        if seen.count(d) > 1:
            raise SubmissionError(f"{where}: distance {d:g} m appears {seen.count(d)} times")
    missing = [d for d in protocol.distances_m if d not in seen]
    if missing:
        required = ", ".join(f"{d:g}" for d in protocol.distances_m)
        raise SubmissionError(f"{where}: missing distance(s) {', '.join(f'{d:g}' for d in missing)} m (protocol {protocol.name!r} requires {required} m)")
    extra = [d for d in seen if d not in protocol.distances_m]
    if extra:
        raise SubmissionError(f"{where}: distance {extra[0]:g} m is not one of protocol {protocol.name!r}'s distances")
    rows = sorted(cond["per_distance"], key=lambda r: r["distance_m"])
    environments = protocol.n_environments if protocol.n_environments is not None else cond["n_environments"]
    for r in rows:  # the paired design: every environment is placed once at every distance
        if r["n_images"] != environments:
            raise SubmissionError(f"{where}: n_images {r['n_images']} at {r['distance_m']:g} m, but a collection of "
                                  f"{environments} environments has {environments} images at each distance")
    for r in rows:
        if r["ap"] > r["ap50"] + AP_TOLERANCE:
            raise SubmissionError(
                f"{where}: AP {r['ap']:.6f} exceeds AP50 {r['ap50']:.6f} at {r['distance_m']:g} m (AP averages IoU 0.50:0.95, so it cannot)"
            )
    expected = _finite_or_none(od50([r["distance_m"] for r in rows], [r["ap"] for r in rows]))
    claimed = cond["od50_m"]
    if (expected is None) != (claimed is None) or (
        expected is not None and abs(expected - claimed) > OD50_TOLERANCE_M
    ):
        show = "inf" if expected is None else f"{expected:.3f} m"
        raise SubmissionError(f"{source}: conditions.{cname}.od50_m = {claimed} does not follow from its AP per distance (OD50 = {show})")
    _check_interval(cname, cond, source)
    if protocol.n_environments is not None and cond["n_environments"] != protocol.n_environments:
        raise SubmissionError(
            f"{source}: conditions.{cname}.n_environments = {cond['n_environments']}, but protocol {protocol.name!r} has {protocol.n_environments} environments"
        )


def _check_interval(cname: str, cond: dict, source: str) -> None:
    """``od50_ci95_m`` = [lo, hi] is ordered (null = +inf) and holds ``od50_m`` (null =
    +inf; 1 mm of rounding): an interval that excludes its own estimate says the numbers were
    not made together. ``od50_sd_m`` is 0 only where the interval has no finite width (the
    SD is of the finite resampled OD50s; the interval holds the infinite ones too)."""
    def show(v: float) -> str:
        return "null" if v == math.inf else f"{v:g}"

    lo, hi = (math.inf if v is None else float(v) for v in cond["od50_ci95_m"])
    where = f"{source}: conditions.{cname}"
    for field, value in (("od50_m", cond["od50_m"]), ("od50_sd_m", cond["od50_sd_m"]), ("od50_ci95_m[0]", lo),
                         ("od50_ci95_m[1]", hi)):
        if value is not None and math.isfinite(value) and value > MAX_OD50_M:
            raise SubmissionError(f"{where}.{field} = {value:g} m is beyond any OD50 an AP curve gives "
                                  f"(at most {MAX_OD50_M:g} m; null stands for +inf)")
    if lo > hi:
        raise SubmissionError(f"{where}.od50_ci95_m = [{show(lo)}, {show(hi)}] is reversed (lo > hi)")
    value = math.inf if cond["od50_m"] is None else float(cond["od50_m"])
    if not (lo - OD50_TOLERANCE_M <= value <= hi + OD50_TOLERANCE_M):
        raise SubmissionError(f"{where}.od50_m = {show(value)} lies outside its od50_ci95_m [{show(lo)}, {show(hi)}]")
    if cond["od50_sd_m"] == 0 and math.isfinite(hi) and hi - lo > OD50_TOLERANCE_M:
        raise SubmissionError(f"{where}.od50_sd_m = 0, but its od50_ci95_m [{show(lo)}, {show(hi)}] has a width "
                              "(identical resamples have no spread)")


def validate_submission(
    data: object, *, protocols: dict[str, Protocol] | None = None, source: str = "submission", now: datetime | None = None
) -> dict:
    """Schema and consistency checks of a parsed submission; returns it unchanged.

    ``now``: the checker's clock (default: the current UTC time); ``created_at`` may be at
    most :data:`CLOCK_TOLERANCE` ahead of it.
    """
    check_values(data, source)
    check_schema(data, source)
    assert isinstance(data, dict)
    check_name(data["name"])
    try:
        created = datetime.strptime(data["created_at"], "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=timezone.utc)
    except ValueError:
        raise SubmissionError(f"{source}: created_at {data['created_at']!r} is not a valid UTC date and time") from None
    now = datetime.now(timezone.utc) if now is None else now
    if created > now + CLOCK_TOLERANCE:
        raise SubmissionError(f"{source}: created_at {data['created_at']} is in the future (now {now:%Y-%m-%dT%H:%M:%SZ})")
    if created < EARLIEST_CREATED_AT:
        raise SubmissionError(f"{source}: created_at {data['created_at']} is before {EARLIEST_CREATED_AT:%Y-%m-%d}, "
                              "before the protocol it is scored on existed (Liu et al., EI 2023)")
    _check_named_fields(data, source)
    _check_package_version(data["package_version"], source)
    if "software" in data:
        _check_software(data["software"], source)
    _check_camera(data, source)
    _check_detector(data, source)
    protocols = load_protocols() if protocols is None else protocols
    col = data["collection"]
    protocol = protocols.get(col["protocol"])
    if protocol is None:
        raise SubmissionError(
            f"{source}: protocol {col['protocol']!r} is not accepted by this leaderboard (accepted: {', '.join(protocols)})"
        )
    if col["manifest_sha256"] not in protocol.manifests_sha256:
        raise SubmissionError(
            f"{source}: collection.manifest_sha256 {col['manifest_sha256'][:12]}... is not an accepted manifest of protocol {protocol.name!r}"
        )
    if col["name"] not in protocol.collection_names:  # (a manifest's name is part of its sha256)
        raise SubmissionError(f"{source}: collection.name {col['name']!r} is not the name of protocol {protocol.name!r}'s "
                              f"collection ({', '.join(map(repr, protocol.collection_names))})")
    conditions = data["conditions"]
    for required in protocol.required_conditions:
        if required not in conditions:
            raise SubmissionError(
                f"{source}: conditions: missing required condition {required!r} (protocol {protocol.name!r} requires: {', '.join(protocol.required_conditions)})"
            )
    for cname in sorted(conditions):
        if cname not in protocol.conditions:
            raise SubmissionError(
                f"{source}: conditions.{cname}: not a condition of protocol {protocol.name!r} (allowed: {', '.join(protocol.conditions)})"
            )
        _check_condition(cname, conditions[cname], protocol, source)
    seen: dict[str, str] = {}
    for cname in sorted(conditions):
        digest = conditions[cname]["detections_sha256"]
        if digest in seen:
            raise SubmissionError(
                f"{source}: conditions.{seen[digest]} and conditions.{cname} have the same detections_sha256 {digest[:12]}... (each condition is its own run)"
            )
        seen[digest] = cname
    return data


def system_identity(data: dict) -> tuple:
    """What makes two submissions one camera system: camera spec, detector (file and input
    size) and collection manifest. Another run of it (another seed, another machine, another
    name) is a reproduction of that entry, not a second row."""
    return (data["camera"]["spec_sha256"], data["detector"]["sha256"], str(data["detector"]["input_size"]),
            data["collection"]["manifest_sha256"])


def duplicate_problem(data: dict, other: dict, other_name: str) -> str | None:
    """Why ``data`` may not stand beside ``other`` (an entry named ``other_name``), or None."""
    if system_identity(data) == system_identity(other):
        return (f"duplicate: {other_name} already ranks the same camera spec, detector and collection (a reproduction "
                f"of it is not a second row; to replace it, remove {other_name} first)")
    theirs = {c["detections_sha256"]: name for name, c in other["conditions"].items()}
    for cname, cond in sorted(data["conditions"].items()):
        if cond["detections_sha256"] in theirs:
            return (f"duplicate: conditions.{cname}.detections_sha256 {cond['detections_sha256'][:12]}... is the "
                    f"detections of {other_name} (conditions.{theirs[cond['detections_sha256']]}); each run is its own")
    return None


def check_not_duplicate(data: dict, leaderboard_dir: str | Path, *, path: str | Path | None = None) -> None:
    """Refuse a name already taken, the same system (:func:`system_identity`) under another
    name, or another entry's detections.

    ``path``: where ``data`` was read from; the file itself is not its own duplicate.
    """
    folder = Path(leaderboard_dir) / SUBMISSIONS
    target = folder / f"{data['name']}.json"
    own = Path(path).resolve() if path is not None else None
    if target.exists() and target.resolve() != own:
        raise SubmissionError(f"duplicate name: {target} already exists (choose another --name)")
    for other in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        if other.resolve() in (own, target.resolve()):
            continue
        try:
            problem = duplicate_problem(data, json.loads(other.read_text(encoding="utf-8")), other.name)
        except (ValueError, KeyError, TypeError, AttributeError, OSError):
            continue  # a broken file is reported when the table is rendered
        if problem:
            raise SubmissionError(problem)


def verify_detections(data: dict, detections: list[str | Path], groundtruth: str | Path, *, source: str = "submission") -> list[str]:
    """Recompute AP of the conditions whose detections files are given; returns those conditions.

    Each file is matched to a condition by its sha256; ``groundtruth`` is the collection's
    ground truth on the camera's grid (a run folder's ``groundtruth.json``).
    """
    from benchmark.scoring import ap_by_distance

    try:
        gt = json.loads(Path(groundtruth).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SubmissionError(f"groundtruth {groundtruth}: cannot read ({type(exc).__name__})") from None
    gt_manifest = (gt.get("info") or {}).get("manifest_sha256") if isinstance(gt, dict) else None
    if gt_manifest is not None and gt_manifest != data["collection"]["manifest_sha256"]:
        raise SubmissionError(f"groundtruth {Path(groundtruth).name} is of manifest {gt_manifest[:12]}..., not the submission's collection")
    by_hash = {c["detections_sha256"]: name for name, c in data["conditions"].items()}
    verified = []
    for path in detections:
        path = Path(path)
        if not path.is_file():
            raise SubmissionError(f"detections {path}: no such file")
        digest = sha256_file(path)
        cname = by_hash.get(digest)
        if cname is None:
            raise SubmissionError(f"detections {path.name} (sha256 {digest[:12]}...) is not the file any condition was computed from")
        try:
            dets = json.loads(path.read_text(encoding="utf-8"))
            rows = ap_by_distance(gt, dets, backend=data["scoring"]["backend"])
        except (ValueError, KeyError, TypeError) as exc:
            raise SubmissionError(f"detections {path.name}: cannot score ({type(exc).__name__}: {exc})".splitlines()[0]) from None
        recomputed = {float(r["distance_m"]): r for r in rows}
        for claimed in data["conditions"][cname]["per_distance"]:
            r = recomputed.get(float(claimed["distance_m"]))
            if r is None or r["n_images"] != claimed["n_images"]:
                raise SubmissionError(f"{source}: conditions.{cname}: the ground truth has no images at {claimed['distance_m']:g} m matching n_images {claimed['n_images']}")
            for key in ("ap", "ap50"):
                if not abs(float(r[key]) - claimed[key]) <= AP_TOLERANCE:
                    raise SubmissionError(
                        f"{source}: conditions.{cname}: {key.upper()} at {claimed['distance_m']:g} m is {claimed[key]:.6f} "
                        f"but {float(r[key]):.6f} recomputed from {path.name}"
                    )
        verified.append(cname)
    return verified


def check_shipped(data: dict, path: str | Path, protocols: dict[str, Protocol], *, recompute: bool = True,
                  source: str | None = None) -> list[str]:
    """The conditions whose shipped detections (``<name>.detections/<condition>.json.gz`` beside
    ``path``) match their sha256 and, with ``recompute``, give every AP, AP50, image count, OD50
    and environment count the submission claims (:func:`benchmark.leaderboard.detections.recompute`);
    one line refuses the first that does not. A submission that ships none is refused ("carries
    no detections") unless its protocol's ``made_before_detections`` pins this very file (its
    canonical sha256: an edited copy is refused): then [] and a :class:`NoDetectionsWarning`."""
    from benchmark.leaderboard.detections import pack_path, read_pack, recompute as recompute_pack

    path = Path(path)
    source = source or path.name
    protocol = protocols[data["collection"]["protocol"]]
    shipped = {c: cond.get("shipped_detections_sha256") for c, cond in sorted(data["conditions"].items())}
    if not any(shipped.values()):
        pinned = protocol.made_before_detections.get(data["name"])
        if pinned is not None and pinned == canonical_sha256(data):
            warnings.warn(NoDetectionsWarning(
                f"{source} was made before detections shipped (protocol {protocol.name!r}, made_before_detections): "
                "its AP is accepted as published, not recomputed, and compare against it is refused "
                "(docs/leaderboard.md, \"Where the references' detections come from\")"), stacklevel=2)
            return []
        edited = " (and it is not the file pinned as made before detections shipped: edited?)" if pinned else ""
        raise SubmissionError(f"{source}: carries no detections: its AP cannot be recomputed{edited}; "
                              "`benchmark submit` writes them beside the file")
    missing = [c for c, digest in shipped.items() if not digest]
    if missing:
        raise SubmissionError(f"{source}: conditions.{missing[0]} carries no detections (no shipped_detections_sha256): "
                              "its AP cannot be recomputed")
    for cname, digest in shipped.items():
        where = pack_path(path, cname)
        label = f"{where.parent.name}/{where.name}"
        if not recompute:  # the checksum alone (rendering): the bytes --check recomputed from
            _check_checksum(where, digest, label)
            continue
        recompute_pack(data, cname, read_pack(where, expected_sha256=digest, source=label), source=source)
    return list(shipped)


def _check_checksum(path: Path, digest: str, label: str) -> None:
    from benchmark.leaderboard.detections import MAX_PACK_BYTES

    if not path.is_file():
        raise SubmissionError(f"{label}: no such file (the submission's detections are missing)")
    if path.stat().st_size > MAX_PACK_BYTES:
        raise SubmissionError(f"{label}: over the {MAX_PACK_BYTES // (1024 * 1024)} MB limit")
    actual = sha256_file(path)
    if actual != digest:
        raise SubmissionError(f"{label}: sha256 {actual[:12]}... is not the submission's {digest[:12]}... (the file changed)")


def check_submission_file(
    path: str | Path,
    *,
    leaderboard_dir: str | Path | None = None,
    detections: list[str | Path] = (),
    groundtruth: str | Path | None = None,
) -> dict:
    """Everything ``benchmark submit --check`` does; returns the submission. Touches no file.

    AP is recomputed from the detections shipped beside ``path`` (:func:`check_shipped`; a
    submission pinned as made before detections shipped warns with :class:`NoDetectionsWarning`)."""
    path = Path(path)
    data = read_submission_file(path)
    protocols = load_protocols(leaderboard_dir)
    validate_submission(data, protocols=protocols, source=path.name)
    if leaderboard_dir is not None:
        check_not_duplicate(data, leaderboard_dir, path=path)
    check_shipped(data, path, protocols, source=path.name)
    if detections:
        if groundtruth is None:
            raise SubmissionError("--detections needs --groundtruth (the run folder's groundtruth.json)")
        verify_detections(data, list(detections), groundtruth, source=path.name)
    return data
