"""One writer per collection: ``<collection>/generate.lock``; one per run or sweep folder:
``<folder>/benchmark.lock`` (:func:`folder_lock`, taken by ``benchmark run`` and ``sweep``).

``metricscenes generate`` holds an exclusive ``flock`` on the lock file for as long as it
writes, and the file says who holds it (PID, host, the process's start time, since when,
the command).
A second writer is refused with one line naming the holder. The kernel drops the
``flock`` when its holder dies, however it dies, so a lock file left by a killed run is
stale and the next writer takes it over (with a notice); where ``flock`` is not shared
(some network file systems), a lock naming a process that is still alive on this host
(same PID and start time, so a reused PID does not count) is refused too. The file is
removed when its holder finishes, on errors and interrupts included.
"""

from __future__ import annotations

import json
import os
import socket
import time
from contextlib import contextmanager
from pathlib import Path

from metricscenes.store import CollectionError

LOCK_FILE = "generate.lock"
OUTPUT_LOCK_FILE = "benchmark.lock"  # a run or sweep folder's (benchmark writes no collection)


class LockError(CollectionError):
    """The collection is locked by another writer (one-line message naming it)."""


def _process_start(pid: int) -> int | None:
    """Start time of a process in clock ticks since boot (Linux), or None if unknown."""
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])
    except (OSError, IndexError, ValueError):
        return None


def _alive(holder: dict) -> bool:
    """Is the process a lock file names still running (on this host)?"""
    pid = holder.get("pid")
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass  # exists, another user's
    except OSError:
        return False
    started = holder.get("process_start")
    now = _process_start(pid)
    return started is None or now is None or started == now


def writer(root: str | Path, lock_file: str = LOCK_FILE) -> dict | None:
    """Who its lock file says is writing ``root`` (PID, host, since, command), or None: no
    lock file, or a stale one (its process gone, on this host). Reads the file only: taking
    even a shared ``flock`` could turn a writer starting at that moment away."""
    try:
        holder = json.loads((Path(root) / lock_file).read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if not isinstance(holder, dict) or (holder.get("host") == socket.gethostname() and not _alive(holder)):
        return None
    return holder


def output_lock(root: str | Path, command: str, what: str, notice=None):
    """:func:`folder_lock` on a run or sweep folder's ``benchmark.lock``."""
    return folder_lock(root, command, what, notice=notice, lock_file=OUTPUT_LOCK_FILE)


def describe(holder: dict | None) -> str:
    if not holder:
        return "a holder that wrote no details"
    since = f" since {holder['since']}" if holder.get("since") else ""
    return f"PID {holder.get('pid')} on host {holder.get('host')}{since}"


def _read(fd: int) -> dict | None:
    try:
        data = json.loads(os.pread(fd, 4096, 0).decode())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    return data if isinstance(data, dict) else None


def _refusal(path: Path, holder: dict | None, command: str, what: str) -> LockError:
    holding = (holder or {}).get("command") or command
    return LockError(f"{path.parent}: another `{holding}` is writing this {what} ({describe(holder)}; lock file "
                     f"{path}); wait for it or stop it")


def _acquire(path: Path, notice, command: str, what: str) -> int:
    import fcntl

    host = socket.gethostname()
    for _ in range(20):
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise _refusal(path, _read(fd), command, what) from None
            try:  # the holder before us may have removed the file we opened: lock the one at `path`
                same = os.fstat(fd).st_ino == os.stat(path).st_ino
            except FileNotFoundError:
                same = False
            if not same:
                os.close(fd)
                continue
            previous = _read(fd)
            if previous and previous.get("pid") != os.getpid():
                if previous.get("host") == host and _alive(previous):
                    raise _refusal(path, previous, command, what)
                if notice:
                    reason = "no longer running" if previous.get("host") == host else "its lock is not held"
                    notice(f"taking over the stale lock of {describe(previous)} ({reason})")
            me = {"pid": os.getpid(), "host": host, "process_start": _process_start(os.getpid()),
                  "since": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "command": command}
            os.ftruncate(fd, 0)
            os.pwrite(fd, (json.dumps(me) + "\n").encode(), 0)
            return fd
        except BaseException:
            try:
                os.close(fd)
            except OSError:
                pass
            raise
    raise LockError(f"{path.parent}: could not take the lock {path} (it keeps being replaced)")


def collection_lock(root: str | Path, notice=None):
    """Hold ``root/generate.lock`` for the duration of the block (``root`` must exist);
    raise :class:`LockError` if another writer holds it. ``notice`` gets one line when
    a stale lock is taken over."""
    return folder_lock(root, "metricscenes generate", "collection", notice=notice)


@contextmanager
def folder_lock(root: str | Path, command: str, what: str, notice=None, lock_file: str = LOCK_FILE):
    """Hold ``root/lock_file`` for the duration of the block (``root`` must exist): one
    ``command`` writing the folder (``what`` it is, for the message) at a time;
    :class:`LockError`, one line naming the holder, if another holds it."""
    path = Path(root) / lock_file
    fd = _acquire(path, notice, command, what)
    try:
        yield path
    finally:
        try:  # remove it while still holding it, so no one locks an orphaned file
            if os.fstat(fd).st_ino == os.stat(path).st_ino:
                os.unlink(path)
        except OSError:
            pass
        os.close(fd)
