"""What every command line of the project shares: the one-line error and the progress bar.

Both ``metricscenes`` and ``benchmark`` use these (benchmark imports metricscenes, never
the other way round).
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from typing import NoReturn

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from rich.text import Text

_stderr = Console(stderr=True)


def fail(message: str, code: int = 2) -> NoReturn:
    """``error: <message>`` on stderr, exit ``code``, no traceback.

    The message is plain text (a ``[day, dusk]`` in it is not rich markup) folded to one
    line: a refusal is one line however the exception that carried it was worded.
    """
    one_line = " ".join(str(message).split())
    _stderr.print(Text.assemble(("error:", "bold red"), " ", one_line), highlight=False, soft_wrap=True)
    raise typer.Exit(code)


def cannot_write(out, exc: OSError) -> str:
    """The one line of an OSError met writing ``out`` (a full disk, a folder that is not
    writable): the file it names where it names one, and the reason in words (an OSError
    raised with a message only, such as shutil's on a symbolic link, keeps its message)."""
    where = f" ({exc.filename})" if exc.filename else ""
    return f"cannot write {out}{where}: {exc.strerror or str(exc) or type(exc).__name__}"


class LogProgress:
    """Progress for a log file: a plain line every ``step`` of the units or every ``every_s``
    seconds, whichever comes first (units done, elapsed, estimated remaining). What
    :func:`progress_bar` gives where its console is not a terminal (``rich`` would print
    nothing until the end). The first count reported is work found done (a resumed run's):
    the remaining time is estimated from the units done after it."""

    def __init__(self, console: Console, step: float = 0.05, every_s: float = 30.0, clock=time.monotonic):
        self.console, self.step, self.every_s, self.clock = console, step, every_s, clock
        self.tasks: dict[int, dict] = {}

    def add_task(self, description: str, total: float | None = None, **_) -> int:
        now = self.clock()
        self.tasks[len(self.tasks)] = {"description": description, "total": total, "completed": 0,
                                       "started": now, "printed_at": now, "printed_fraction": 0.0, "found": None}
        return len(self.tasks) - 1

    def update(self, task: int, completed: float | None = None, total: float | None = None,
               description: str | None = None, **_) -> None:
        t = self.tasks[task]
        for key, value in (("completed", completed), ("total", total), ("description", description)):
            if value is not None:
                t[key] = value
        now = self.clock()
        if t["found"] is None and completed is not None:
            t["found"] = (t["completed"], now)
        fraction = t["completed"] / t["total"] if t["total"] else 0.0
        done = bool(t["total"]) and t["completed"] >= t["total"]
        if done or fraction >= t["printed_fraction"] + self.step or now - t["printed_at"] >= self.every_s:
            t["printed_at"], t["printed_fraction"] = now, fraction
            self.console.print(self.line(t, now), highlight=False, soft_wrap=True, markup=False)

    def advance(self, task: int, advance: float = 1) -> None:
        self.update(task, completed=self.tasks[task]["completed"] + advance)

    @staticmethod
    def line(t: dict, now: float) -> str:
        elapsed = now - t["started"]
        if not t["total"]:
            return f"{t['description']}: {t['completed']:g} done, {_duration(elapsed)} elapsed"
        fraction = t["completed"] / t["total"]
        found, found_at = t["found"] or (0, t["started"])
        rate = (t["completed"] - found) / (now - found_at) if now > found_at else 0.0
        left = f", about {_duration((t['total'] - t['completed']) / rate)} left" if 0 < fraction < 1 and rate > 0 else ""
        return (f"{t['description']}: {t['completed']:g}/{t['total']:g} ({100 * fraction:.0f} %), "
                f"{_duration(elapsed)} elapsed{left}")


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min" if seconds >= 3600 else f"{seconds // 60} min {seconds % 60:02d} s"


@contextmanager
def progress_bar(console: Console, disable: bool = False):
    """A rich progress bar that vanishes if the block fails, so an error stays one line;
    where ``console`` is not a terminal (a log), plain lines instead (:class:`LogProgress`)."""
    if not disable and not console.is_terminal:
        yield LogProgress(console)
        return
    bar = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                   TimeElapsedColumn(), TimeRemainingColumn(), console=console, transient=False, disable=disable)
    with bar:
        try:
            yield bar
        except BaseException:
            bar.live.transient = True
            raise


SCHEDULER_HELP = ("run on dask: 'local' (a LocalCluster of --workers processes) or tcp://HOST:PORT of a running "
                  "scheduler, whose workers see --out at the same path (docs/performance.md)")
"""``--scheduler`` of ``metricscenes generate`` and ``benchmark sweep``."""
