"""A collection folder's files outside its arrays (:mod:`metricscenes.store`'s layout): where
outputs may go (:func:`file_in_the_way`, :func:`collection_containing`), loading and checking
the resolved manifest, the ground truth and the progress records, and
:func:`verify_collection`, which checks a whole collection."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import yaml

from metricscenes.checked_read import (
    GROUNDTRUTH_FILE, PROGRESS_DIR, RADIANCE_STORE, RESOLVED_MANIFEST_FILE, CollectionError, read_checked,
)
from metricscenes.groundtruth_checks import groundtruth_problems
from metricscenes.manifest import Manifest, ManifestError, manifest_sha256, parse_manifest
from metricscenes.records import ResolvedManifest, resolved_content_sha256

ATTRIBUTES_UPGRADE_NOTE = ("its arrays' attributes have no recorded sha256 (the collection was written before they "
                           "had one): rerun `metricscenes generate` with its manifest to record them (it renders "
                           "nothing when they are the ones written)")


def file_in_the_way(out_dir: str | Path, what: str = "--out") -> str | None:
    """Why ``out_dir`` cannot be a folder (it is a file, or a path through one), or None;
    ``what``: the option that named it."""
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        return f"{what} {out_dir} is a file, not a folder"
    for parent in out_dir.absolute().parents:
        if parent.exists():
            return None if parent.is_dir() else f"{what} {out_dir}: {parent} is a file, not a folder"
    return None


def collection_containing(path: str | Path) -> Path | None:
    """The collection folder that ``path`` is (or lies inside), or None. A folder is a
    collection if it holds a resolved manifest, a radiance store or a generate stamp."""
    p = Path(os.path.abspath(Path(path).expanduser())).resolve()
    for folder in (p, *p.parents):
        if ((folder / RESOLVED_MANIFEST_FILE).is_file() or (folder / RADIANCE_STORE).is_dir()
                or (folder / PROGRESS_DIR / "manifest_sha256").is_file()):
            return folder
    return None



def _load_resolved(root: Path) -> ResolvedManifest:
    """The resolved manifest, parsed and checked against its own hashes (the manifest it
    holds is parsed by :func:`_parse_manifest`)."""
    try:
        resolved = yaml.safe_load((root / RESOLVED_MANIFEST_FILE).read_text())
    except (OSError, yaml.YAMLError, UnicodeDecodeError) as exc:
        raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE} is corrupted ({type(exc).__name__})") from None
    if (not isinstance(resolved, dict) or not isinstance(resolved.get("manifest"), dict)
            or not isinstance(resolved.get("arrays"), dict) or "manifest_sha256" not in resolved):
        raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE} lacks 'manifest', 'manifest_sha256' or 'arrays'")
    if manifest_sha256(resolved["manifest"]) != resolved["manifest_sha256"]:
        raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE}: its manifest does not match manifest_sha256 "
                              "(edited or damaged)")
    content = resolved.get("content_sha256")  # absent in collections written before it
    if content is not None and content != resolved_content_sha256(resolved):
        raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE} does not match its content_sha256 (edited or damaged)")
    attributes = resolved.get("attributes_sha256")  # absent in collections written before it
    if attributes is not None and not (isinstance(attributes, dict)
                                       and all(isinstance(v, str) for v in attributes.values())):
        raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE}: attributes_sha256 is not a mapping of hashes")
    groups = resolved.get("light_groups")  # absent where the collection holds all of its manifest's
    if groups is not None and not (isinstance(groups, list) and all(isinstance(g, str) for g in groups)):
        raise CollectionError(f"{root}: {RESOLVED_MANIFEST_FILE}: light_groups is not a list of light groups")
    return ResolvedManifest.from_dict(resolved)


def _parse_manifest(root: Path, resolved: ResolvedManifest) -> Manifest:
    """The manifest a collection was rendered from, validated as a manifest file is."""
    try:
        return parse_manifest(resolved.manifest_json, source=RESOLVED_MANIFEST_FILE)
    except ManifestError as exc:
        raise CollectionError(f"{root}: {exc}") from None


def _load_groundtruth(root: Path) -> tuple[dict, str]:
    """The COCO ground truth and the sha256 of its file's bytes."""
    try:
        raw = (root / GROUNDTRUTH_FILE).read_bytes()
        groundtruth = json.loads(raw)
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise CollectionError(f"{root}: {GROUNDTRUTH_FILE} is corrupted ({type(exc).__name__})") from None
    try:
        ok = (all({"scene_id", "id", "environment_id", "distance_m", "width", "height"} <= set(i)
                  for i in groundtruth["images"])
              and all({"image_id", "bbox"} <= set(a) for a in groundtruth["annotations"]))
    except (KeyError, TypeError):
        ok = False
    if not ok:
        raise CollectionError(f"{root}: {GROUNDTRUTH_FILE} is not a collection's COCO ground truth")
    return groundtruth, hashlib.sha256(raw).hexdigest()


def _progress_arrays(root: Path) -> tuple[dict[str, str], dict[str, str]]:
    """The array hashes and attribute hashes the progress records hold (what verify falls
    back on when the resolved manifest is unusable)."""
    arrays, attributes = {}, {}
    for record in sorted((root / PROGRESS_DIR).glob("*.json")):
        try:
            data = json.loads(record.read_text())
            arrays.update(data["arrays"])
            attributes.update(data.get("attributes") or {})
        except (OSError, ValueError, KeyError, TypeError, AttributeError):
            continue
    return arrays, attributes


def upgrade_notes(path: str | Path) -> list[str]:
    """What an intact collection written by an older version does not record yet, and how to
    record it (one line each): its arrays' attribute hashes."""
    try:
        resolved = _load_resolved(Path(path))
    except CollectionError:
        return []
    return [ATTRIBUTES_UPGRADE_NOTE] if resolved.attributes_sha256 is None and resolved.arrays else []


def unfinished_generation(root: str | Path) -> str | None:
    """What a collection whose ``generate`` has not finished holds so far (units recorded in
    ``progress/``; the resolved manifest and ground truth come after the last), else None."""
    root = Path(root)
    if (root / RESOLVED_MANIFEST_FILE).exists() or not (root / PROGRESS_DIR).is_dir():
        return None
    done = len(list((root / PROGRESS_DIR).glob("*.json")))
    return (f"its generation has not finished ({done} units done; {RESOLVED_MANIFEST_FILE} and {GROUNDTRUTH_FILE} "
            "are written after the last): rerun `metricscenes generate` to finish it")


def verify_collection(path: str | Path) -> list[str]:
    """Check a whole collection; return every problem, one line each naming its scene
    (plates: their environment): the resolved manifest (parses, manifest and content
    hashes), every recorded array (sha256; masks too), and the ground truth (sha256, plan,
    boxes recomputed from the masks), every array's attributes (their recorded sha256,
    where the collection records them). Empty: nothing is wrong."""
    import zarr

    root = Path(path)
    if not root.is_dir():
        return [f"{root}: no such collection folder"]
    resolved = groundtruth = None
    unfinished = unfinished_generation(root)
    problems = [unfinished] if unfinished else []  # (then its units' arrays are checked against their records)
    try:
        if not unfinished:
            resolved = _load_resolved(root)
            _parse_manifest(root, resolved)
    except CollectionError as exc:
        problems.append(str(exc).removeprefix(f"{root}: "))
    try:
        if not unfinished or (root / GROUNDTRUTH_FILE).exists():
            groundtruth = _load_groundtruth(root)
    except CollectionError as exc:
        problems.append(str(exc).removeprefix(f"{root}: "))
    if resolved is not None:
        expected, attributes = resolved.arrays, resolved.attributes_sha256
        fallback = ""  # it records them: an array it lists without them fails the check
    else:
        expected, attributes = _progress_arrays(root)
        fallback = None  # what the records hold; older records hold none
    if not expected:
        problems.append("no recorded array hashes to check (manifest.resolved.yaml and progress/ are unusable)")
    try:
        group = zarr.open_group(str(root / RADIANCE_STORE), mode="r")
    except Exception as exc:
        return [*problems, f"{RADIANCE_STORE} is missing or unreadable ({type(exc).__name__})"]
    for array_path, sha in sorted(expected.items()):
        kind, _, rest = array_path.partition("/")
        unit = rest.split("/")[0]
        try:
            where = f"environment {unit}" if kind in ("plates", "wide_plates") else f"scene {unit}"
            read_checked(root, group, array_path, sha, where,
                         None if attributes is None else attributes.get(array_path, fallback))
        except CollectionError as exc:
            problems.append(str(exc))
    if groundtruth is not None:  # without a usable resolved manifest, boxes are still checked against the masks
        problems += groundtruth_problems(root, group, *groundtruth, resolved)
    # A mask listed by its array hash and by the ground-truth check is one problem.
    return list(dict.fromkeys(problems))
