"""Atomic text writes and file digests, shared by metricscenes and benchmark.

A write goes to a temporary file in the target's folder, is flushed to disk, then
``os.replace``-d over the target (atomic on POSIX and Windows), so an interrupted write
leaves the old file intact and readers never see half a file.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path


def write_atomic(path: str | Path, text: str | bytes) -> Path:
    """Write ``text`` to ``path`` through a temporary file and ``os.replace``; returns ``path``.

    UTF-8 with the text's own ``\\n`` line endings on every platform (same inputs → same bytes);
    bytes are written as they are.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # mkstemp: a name no other process or thread writing the same file can take
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(text.encode("utf-8") if isinstance(text, str) else text)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)  # mkstemp makes 0600 files; results and tables are meant to be read
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def sha256_file(path: str | Path) -> str:
    """sha256 (hex) of a file's bytes, read 1 MiB at a time."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_text_capped(path: str | Path, max_bytes: int, what: str) -> str:
    """The UTF-8 text of a small input file (a manifest, a protocols file), read no further
    than ``max_bytes`` + 1: a one-line ValueError for a larger file or one that is not UTF-8
    (an OSError where it cannot be read)."""
    path = Path(path)
    with open(path, "rb") as f:
        raw = f.read(max_bytes + 1)
    if len(raw) > max_bytes:
        raise ValueError(f"{path}: larger than {max_bytes / 2**20:g} MiB: not a {what}")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start})") from None
