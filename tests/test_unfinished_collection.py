"""A collection whose `generate` has not finished (metric-300 takes hours): opening it, `info`
and `verify` say how far it got and who is generating it, instead of calling the files that
come after the last unit corrupted; the units done are still checked."""

import json
import os
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from metricscenes.lock import _process_start, writer
from metricscenes.store import (GROUNDTRUTH_FILE, PROGRESS_DIR, RESOLVED_MANIFEST_FILE, Collection, CollectionError,
                                verify_collection)

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[1]


def _unfinished(smoke_collection, tmp_path) -> Path:
    """smoke as a generate leaves it midway: env001's units not yet done, nothing written after the last."""
    root = tmp_path / "unfinished"
    shutil.copytree(smoke_collection, root)
    for name in (RESOLVED_MANIFEST_FILE, GROUNDTRUTH_FILE):
        (root / name).unlink()
    for record in (root / PROGRESS_DIR).glob("env001*.json"):
        record.unlink()
    return root


def _lock(root: Path, pid: int, host: str | None = None) -> None:
    (root / "generate.lock").write_text(json.dumps({
        "pid": pid, "host": host or socket.gethostname(), "process_start": _process_start(pid),
        "since": "2026-11-26T13:03:15+0000", "command": "metricscenes generate"}))


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_open_and_verify_say_how_far_generation_got(smoke_collection, tmp_path):
    root = _unfinished(smoke_collection, tmp_path)
    done = len(list((root / PROGRESS_DIR).glob("*.json")))
    assert 0 < done < len(list((Path(smoke_collection) / PROGRESS_DIR).glob("*.json")))
    with pytest.raises(CollectionError, match=rf"its generation has not finished \({done} units done;"):
        Collection.open(root)
    problems = verify_collection(root)
    assert len(problems) == 1 and problems[0].startswith(f"its generation has not finished ({done} units done")
    assert "corrupted" not in problems[0]
    # The units done are still checked against their records.
    chunk = next(p for p in (root / "radiance.zarr" / "insets/env000-d025m/sky_day").rglob("*")
                 if p.is_file() and p.name != "zarr.json")
    data = bytearray(chunk.read_bytes())
    data[len(data) // 2] ^= 0xFF
    chunk.write_bytes(bytes(data))
    problems = verify_collection(root)
    assert len(problems) == 2 and any("insets/env000-d025m/sky_day" in p for p in problems)


def test_writer_is_a_live_lock_holder(tmp_path):
    assert writer(tmp_path) is None  # no lock file
    _lock(tmp_path, os.getpid())
    assert writer(tmp_path)["pid"] == os.getpid()
    _lock(tmp_path, _dead_pid())
    assert writer(tmp_path) is None  # stale: its process is gone
    _lock(tmp_path, 1, host="another-host")  # (can't be checked from here: taken at its word)
    assert writer(tmp_path)["host"] == "another-host"
    (tmp_path / "generate.lock").write_text("{not json")
    assert writer(tmp_path) is None


@pytest.mark.parametrize("command", ["info", "verify"])
def test_cli_names_the_generate_at_work(smoke_collection, tmp_path, command):
    root = _unfinished(smoke_collection, tmp_path)

    def run():
        proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", command, str(root)], capture_output=True,
                              text=True, cwd=REPO, timeout=300)
        assert proc.returncode != 0 and "Traceback" not in proc.stdout + proc.stderr
        return proc.stdout + proc.stderr

    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"])
    try:
        _lock(root, holder.pid)
        out = run()
        assert f"PID {holder.pid} on host {socket.gethostname()} since 2026-11-26T13:03:15+0000 is generating it now" in out
        assert "has not finished" in out
    finally:
        holder.kill()
        holder.wait()
    assert "generating it now" not in run()  # its lock is stale now
