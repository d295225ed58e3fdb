"""Where a command may write: the folders the two packages make, told apart by what they
hold, and the one rule every ``--out`` follows.

- a **collection** (``metricscenes generate``): :func:`metricscenes.store.collection_containing`;
- a **run folder** (``benchmark run``): it holds ``results.json``;
- a **sweep folder** (``benchmark sweep``): it holds ``sweep.json`` or ``sweep.csv`` (written
  when the sweep ends) or ``sweep.started`` (written when it starts, so that a sweep still
  running, or killed, is one too);
- a **leaderboard** (``benchmark submit`` and ``leaderboard``): it holds ``submissions/``
  or ``protocols.yaml``.

The rule (:func:`check_output`): an output may not lie in any of these, unless it is that
command's own kind of folder (``benchmark run --out`` an earlier run folder, which it
replaces) or the one folder the command was given to write into (``benchmark report``'s
page in its results folder). So no command writes into a collection, a leaderboard or
another command's folder. The names are metricscenes' and benchmark's; they live here,
the lower package, so that both packages' commands keep the same rule (benchmark imports
metricscenes, never the reverse).
"""

from __future__ import annotations

import os
from pathlib import Path

COLLECTION, RUN, SWEEP, LEADERBOARD = "collection", "run folder", "sweep folder", "leaderboard"
RUN_MARKERS = ("results.json",)
SWEEP_STAMP = "sweep.started"
SWEEP_MARKERS = ("sweep.json", "sweep.csv", SWEEP_STAMP)
SWEEP_STAMP_TEXT = "a `benchmark sweep` folder: its runs are in runs/, its tables (sweep.csv, sweep.json) when it ends\n"
LEADERBOARD_MARKERS = ("submissions", "protocols.yaml")
WHY = {
    COLLECTION: "collections are written only by `metricscenes generate`",
    RUN: "it holds another run's results",
    SWEEP: "it holds a sweep, whose folders `benchmark sweep` writes",
    LEADERBOARD: "the leaderboard is written only by `benchmark submit` and `benchmark leaderboard`",
}


class OutputError(ValueError):
    """An output that would land where the command may not write (one-line message)."""


def folder_kind(folder: Path) -> str | None:
    """Which of the project's folders ``folder`` is (:data:`COLLECTION`, :data:`RUN`,
    :data:`SWEEP`, :data:`LEADERBOARD`), or None."""
    from metricscenes.store import PROGRESS_DIR, RADIANCE_STORE, RESOLVED_MANIFEST_FILE

    if not folder.is_dir():
        return None
    if ((folder / RESOLVED_MANIFEST_FILE).is_file() or (folder / RADIANCE_STORE).is_dir()
            or (folder / PROGRESS_DIR / "manifest_sha256").is_file()):
        return COLLECTION
    if any((folder / name).is_file() for name in SWEEP_MARKERS):
        return SWEEP
    if any((folder / name).is_file() for name in RUN_MARKERS):
        return RUN
    if (folder / LEADERBOARD_MARKERS[0]).is_dir() or (folder / LEADERBOARD_MARKERS[1]).is_file():
        return LEADERBOARD
    return None


def _absolute(path: str | Path) -> Path:
    return Path(os.path.abspath(Path(path).expanduser())).resolve()


def owners(path: str | Path) -> list[tuple[str, Path]]:
    """(kind, folder) of ``path`` itself and every folder above it that is one of the
    project's folders, nearest first."""
    found = []
    p = _absolute(path)
    for folder in (p, *p.parents):
        kind = folder_kind(folder)
        if kind is not None:
            found.append((kind, folder))
    return found


def check_output(path: str | Path, what: str, own: str | None = None, given: str | Path | None = None) -> Path:
    """``path`` if the command may write there; else :class:`OutputError` naming the folder
    it lies in and why. ``what``: the option as the user typed it (``--out``); ``own``: the
    command's own kind of folder, which ``path`` may be (not lie in); ``given``: a folder
    the command was asked to write into (``path`` may lie in it and in what holds it)."""
    target = _absolute(path)
    allowed = _absolute(given) if given is not None else None
    for kind, folder in owners(target):
        if kind == own and folder == target:
            continue
        if allowed is not None and (folder == allowed or folder in allowed.parents):
            continue
        where = "is" if folder == target else "is inside"
        raise OutputError(f"{what} {path} {where} the {kind} {folder}: {WHY[kind]}; choose a folder outside it")
    return Path(path)


def check_file_output(path: str | Path, what: str, suffixes: tuple[str, ...]) -> Path:
    """A file a command writes (an export, a contact sheet): its suffix is one of
    ``suffixes`` (so the format is known before any work), it is not a folder, and it lies
    outside the project's folders (:func:`check_output`)."""
    from metricscenes.store import file_in_the_way

    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise OutputError(f"{what} {path}: the file name must end in {' or '.join(suffixes)}")
    if path.is_dir():
        raise OutputError(f"{what} {path} is a folder; name a file such as out{suffixes[0]}")
    if problem := file_in_the_way(path.parent, what):
        raise OutputError(problem)
    return check_output(path, what)
