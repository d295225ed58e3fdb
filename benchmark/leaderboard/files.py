"""Tree hashes of the leaderboard folder (atomic writes: :func:`metricscenes.files.write_atomic`)."""

from __future__ import annotations

from pathlib import Path

from metricscenes.files import sha256_file


def tree_sha256(root: str | Path) -> dict[str, str]:
    """``{relative path: sha256}`` of every file under ``root`` (empty if it does not exist)."""
    root = Path(root)
    if not root.exists():
        return {}
    return {p.relative_to(root).as_posix(): sha256_file(p) for p in sorted(root.rglob("*")) if p.is_file()}
