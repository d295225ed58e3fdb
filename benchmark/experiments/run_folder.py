"""What a run keeps in its folder besides its results: the staging folders it writes in
and resumes from, the renames that put a finished run in place, and the clean-up of what a
killed run left (:mod:`benchmark.experiments.run` runs; ``benchmark sweep`` reuses).

A run writes into ``.partial-*`` folders inside its ``--out`` and moves its files into place
only when it succeeded; ``.partial-resume`` (:data:`RESUMABLE_STAGE`) holds each finished
scene (``scenes.jsonl``) for a killed run of the same key to take up. The caller holds the
folder's lock (``benchmark.lock``, :func:`metricscenes.lock.output_lock`) throughout.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from benchmark.result_files import IMAGE_HASHES_FILE

STAGE_PREFIX = ".partial-"
RESUMABLE_STAGE = STAGE_PREFIX + "resume"
"""The staging folder a run writes scene by scene (``scenes.jsonl``: each finished scene's
detections and exposures, written after its image) and a killed run resumes from."""
STAGE_KEY = "resume-key.json"
CHECKPOINT = "scenes.jsonl"


RUN_FILES = ("results.json", "detections.json", "groundtruth.json", "images", IMAGE_HASHES_FILE, "od50.json")
"""What a run writes in its folder (beside its lock and staging folders)."""


def check_run_folder(out_dir) -> Path:
    """``out_dir`` unless it holds files that no run wrote and is not a run folder (no
    ``results.json``): a run would write among them (``generate`` refuses the same case).
    What a killed run leaves (its files, lock and staging folders) is a run's."""
    from metricscenes.lock import OUTPUT_LOCK_FILE

    out_dir = Path(out_dir)
    if not out_dir.is_dir() or (out_dir / "results.json").is_file():
        return out_dir
    other = sorted(p.name for p in out_dir.iterdir()
                   if p.name not in (*RUN_FILES, OUTPUT_LOCK_FILE) and not p.name.startswith(STAGE_PREFIX))
    if other:
        raise ValueError(f"--out {out_dir} holds other files ({', '.join(other[:3])}{', ...' if len(other) > 3 else ''})"
                         " and is not a run folder: choose a new or empty folder")
    return out_dir


def resumable_stage(out_dir: Path, key: dict) -> tuple[Path, bool]:
    """``out_dir``'s resumable staging folder and whether it is resumed: the one a run with
    the same ``key`` left (killed or interrupted), else a new one (another key's is removed)."""
    stage, text = out_dir / RESUMABLE_STAGE, json.dumps(key, sort_keys=True)
    try:
        if (stage / STAGE_KEY).read_text() == text:
            return stage, True
    except (OSError, UnicodeDecodeError):
        pass
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir()
    (stage / STAGE_KEY).write_text(text)
    return stage, False


def remove_stale_stages(out_dir: Path) -> list[Path]:
    """Remove the staging folders (``.partial-*``) that runs killed in ``out_dir`` left
    behind, but the resumable one (:func:`resumable_stage` judges it); the caller holds the
    folder's lock, so none is in use. Returns them."""
    stale = sorted(p for p in out_dir.glob(f"{STAGE_PREFIX}*")
                   if p.is_dir() and not p.is_symlink() and p.name != RESUMABLE_STAGE)
    for folder in stale:
        shutil.rmtree(folder, ignore_errors=True)
    return stale


def remove_finished_leftovers(out_dir: Path, key) -> None:
    """What a run killed after its files moved into place (before it removed its stage and
    lock) left in ``out_dir``, whose run is finished: the staging folders, the resumable one
    where it is of ``key()`` (this very run's :func:`benchmark.experiments.keys.resume_key`: nothing in it is needed; another
    run's is kept for that run), and the stale lock. Untouched while another process holds the lock."""
    from metricscenes.lock import OUTPUT_LOCK_FILE, LockError, output_lock

    if not (out_dir / OUTPUT_LOCK_FILE).exists() and not any(out_dir.glob(f"{STAGE_PREFIX}*")):
        return
    try:
        with output_lock(out_dir, "benchmark sweep", "run folder"):  # (a stale lock is taken over, then removed)
            remove_stale_stages(out_dir)
            stage = out_dir / RESUMABLE_STAGE
            try:
                finished = (stage / STAGE_KEY).read_text() == json.dumps(key(), sort_keys=True)
            except (OSError, UnicodeDecodeError):
                finished = False
            if finished:
                shutil.rmtree(stage, ignore_errors=True)
    except LockError:
        pass  # another run is writing there: its own leftovers are its business


def move_into_place(stage: Path, out_dir: Path, save_images: bool) -> None:
    """A finished run's outputs from its staging folder into ``out_dir``, one rename a file:
    images and their sha256, detections and ground truth, then results.json last (a sweep
    takes a run folder with its results.json as finished). A run without images removes the
    sha256 of an earlier run's, so that those are never read back as this run's."""
    if save_images:
        (out_dir / "images").mkdir(exist_ok=True)
        for image in sorted((stage / "images").iterdir()):
            os.replace(image, out_dir / "images" / image.name)
        os.replace(stage / IMAGE_HASHES_FILE, out_dir / IMAGE_HASHES_FILE)
    else:
        (out_dir / IMAGE_HASHES_FILE).unlink(missing_ok=True)
    for name in ("detections.json", "groundtruth.json", "results.json"):
        os.replace(stage / name, out_dir / name)


def link_or_copy(source: Path, target: Path) -> None:
    """``target`` as a hard link to ``source`` (a camera image is written once, so runs that
    share it need not hold a copy each; a write through one name reaches all, which
    ``images.sha256`` catches where images are read back), or a copy where the file system
    cannot link. A ``target`` already there (a scene a killed run had begun) is
    replaced, never written through: it may be a link to ``source`` itself."""
    target.unlink(missing_ok=True)
    try:
        os.link(source, target)
    except OSError:
        shutil.copyfile(source, target)
