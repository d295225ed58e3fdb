"""Progress in a log: where standard error is not a terminal, generate, run and
sweep print a plain line every 5 % of their units or every 30 s, not a silent rich bar."""

from __future__ import annotations

import io

from rich.console import Console

from cli_output import PROGRESS_LINE, error_lines
from metricscenes.cli_support import LogProgress, progress_bar


def _lines(console_file: io.StringIO) -> list[str]:
    return [line for line in console_file.getvalue().splitlines() if line]


def test_a_log_gets_a_line_every_five_percent_or_thirty_seconds():
    out = io.StringIO()
    now = [0.0]
    progress = LogProgress(Console(file=out, width=200), clock=lambda: now[0])
    task = progress.add_task("rendering quick", total=None)
    for done in range(1, 201):  # 200 units, one every 0.1 s: 20 s in all, so only the 5 % steps print
        now[0] += 0.1
        progress.update(task, completed=done, total=200)
    lines = _lines(out)
    assert len(lines) == 20 and lines[-1].startswith("rendering quick: 200/200 (100 %)")
    assert lines[0] == "rendering quick: 10/200 (5 %), 0 min 01 s elapsed, about 0 min 19 s left"
    now[0] += 31.0  # a long unit: a line after 30 s even without a step
    progress.update(task, description="rendering env000")
    assert _lines(out)[-1].startswith("rendering env000: 200/200")


def test_slow_units_print_every_thirty_seconds():
    out = io.StringIO()
    now = [0.0]
    progress = LogProgress(Console(file=out, width=200), clock=lambda: now[0])
    task = progress.add_task("sweep", total=1000)
    for done in range(1, 11):  # 1 % per 20 s
        now[0] += 20.0
        progress.update(task, completed=done)
    assert len(_lines(out)) == 5  # at 40, 80, 120, 160 and 200 s


def test_a_resumed_run_estimates_from_the_units_it_renders():
    """generate reports the units found done first: they took no time in this run."""
    out = io.StringIO()
    now = [0.0]
    progress = LogProgress(Console(file=out, width=200), clock=lambda: now[0])
    task = progress.add_task("rendering metric-300", total=None)
    progress.update(task, completed=112, total=350)
    for done in range(113, 120):  # then a unit every 100 s
        now[0] += 100.0
        progress.update(task, completed=done)
    assert _lines(out)[-1] == "rendering metric-300: 119/350 (34 %), 11 min 40 s elapsed, about 6 h 25 min left"


def test_progress_bar_is_plain_lines_off_a_terminal_and_rich_on_one():
    with progress_bar(Console(file=io.StringIO())) as bar:
        assert isinstance(bar, LogProgress)
    with progress_bar(Console(file=io.StringIO(), force_terminal=True)) as bar:
        assert not isinstance(bar, LogProgress)
    with progress_bar(Console(file=io.StringIO()), disable=True) as bar:  # --json: nothing at all
        assert not isinstance(bar, LogProgress)


def test_the_tests_pattern_knows_every_progress_line_and_no_error():
    """tests/cli_output.PROGRESS_LINE, which the one-line-error tests skip, is LogProgress's
    line in all its forms (no total; a total with and without an estimate; minutes, hours)."""
    out = io.StringIO()
    now = [0.0]
    progress = LogProgress(Console(file=out, width=300), step=0.0, clock=lambda: now[0])
    counted = progress.add_task("sweep", total=None)
    for done in range(1, 4):
        now[0] += 2000.0
        progress.update(counted, completed=done)
    task = progress.add_task("rendering env000-d025m", total=None)
    for done in range(0, 351, 50):
        now[0] += 700.0
        progress.update(task, completed=done, total=350)
    lines = _lines(out)
    assert {"done," in line for line in lines} == {True, False} and any(" h " in line for line in lines)
    assert all(PROGRESS_LINE.fullmatch(line) for line in lines), lines
    assert error_lines("\n".join([*lines, "error: sweep: 3/4 (75 %), 0 min 02 s elapsed", ""])) == [
        "error: sweep: 3/4 (75 %), 0 min 02 s elapsed"]
