"""What every command line of the project shares: the one-line error and the progress bar.

Both ``metricscenes`` and ``benchmark`` use these (benchmark imports metricscenes, never
the other way round).
"""

from __future__ import annotations

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


@contextmanager
def progress_bar(console: Console, disable: bool = False):
    """A rich progress bar that vanishes if the block fails, so an error stays one line."""
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
