"""A leaderboard folder's submissions, each validated, with what ships beside it: what the
page renders and the references' band is drawn from."""

from __future__ import annotations

from pathlib import Path

from benchmark.leaderboard.protocols import Protocol, load_protocols
from benchmark.leaderboard.validate import SUBMISSIONS, duplicate_problem, read_submission_file, validate_submission


def load_submissions(leaderboard_dir: str | Path, protocols: dict[str, Protocol] | None = None) -> list[dict]:
    """Every ``submissions/*.json``, validated (first failure raises :class:`SubmissionError`), by name;
    two files of one system (or sharing detections) are refused too: one row per system. Each
    one's shipped detections must be there with their sha256 (AP is recomputed by ``submit
    --check``, not at every render), or the file pinned as made before detections shipped."""
    import warnings

    from benchmark.leaderboard.schema import SubmissionError
    from benchmark.leaderboard.validate import NoDetectionsWarning, check_shipped

    folder = Path(leaderboard_dir) / SUBMISSIONS
    protocols = load_protocols(leaderboard_dir) if protocols is None else protocols
    out = []
    paths = sorted(folder.glob("*.json")) if folder.is_dir() else []
    for path in paths:
        sub = validate_submission(read_submission_file(path), protocols=protocols, source=f"{SUBMISSIONS}/{path.name}")
        for earlier in out:
            problem = duplicate_problem(sub, earlier, f"{earlier['name']}.json")
            if problem:
                raise SubmissionError(f"{SUBMISSIONS}/{path.name}: {problem}")
        out.append(sub)
    for path, sub in zip(paths, out):  # then what ships beside each (files, not fields: after every field is known good)
        with warnings.catch_warnings():  # a pinned reference is accepted silently here; --check says so
            warnings.simplefilter("ignore", NoDetectionsWarning)
            check_shipped(sub, path, protocols, recompute=False, source=f"{SUBMISSIONS}/{path.name}")
    return out
