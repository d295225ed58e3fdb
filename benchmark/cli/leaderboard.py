"""``benchmark submit``, ``benchmark leaderboard`` and ``benchmark schema``.

Mounted by ``benchmark/cli/main.py`` through :func:`register`. Every refusal is one line on
stderr and exit code 2; ``--check`` and refused submissions never touch the leaderboard.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Annotated, Optional

import typer

from benchmark.leaderboard.schema import SubmissionError
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES
from benchmark.suggest import did_you_mean
from metricscenes.cli_support import fail


def submit(
    results_dir: Annotated[Optional[Path], typer.Argument(help="a run folder (results.json) or a sweep folder (runs/*/results.json)")] = None,
    name: Annotated[Optional[str], typer.Option(help="system name = file name; put {camera} in it to submit every camera of a sweep")] = None,
    submitter: Annotated[str, typer.Option(help="who submits (name, team, contact)")] = "anonymous",
    camera: Annotated[Optional[str], typer.Option(help="submit only this camera of a sweep")] = None,
    leaderboard: Annotated[Path, typer.Option("--leaderboard", help="leaderboard folder")] = Path("leaderboard"),
    check: Annotated[Optional[Path], typer.Option("--check", help="validate this submission file instead of building one")] = None,
    detections: Annotated[Optional[list[Path]], typer.Option(help="with --check: a detections file to recompute AP from (repeatable, matched to a condition by sha256)")] = None,
    groundtruth: Annotated[Optional[Path], typer.Option(help="with --detections: the ground truth on the camera grid (a run's groundtruth.json)")] = None,
    n_resamples: Annotated[int, typer.Option(min=2, help="bootstrap resamples for OD50's SD")] = BOOTSTRAP_RESAMPLES,
    seed: Annotated[int, typer.Option(min=0, help="bootstrap seed (a sweep's --seed reuses its cached od50.json)")] = 0,
    created_at: Annotated[Optional[str], typer.Option(help="fix the timestamp (YYYY-MM-DDTHH:MM:SSZ); default now, or SOURCE_DATE_EPOCH")] = None,
    mtf: Annotated[bool, typer.Option(help="measure MTF50 on the camera (else the published group)")] = True,
) -> None:
    """Build a leaderboard submission from a run or sweep folder, or --check one."""
    from benchmark.leaderboard import (
        build_submission, check_not_duplicate, check_submission_file, find_runs, group_by_camera, load_protocols,
        write_submission,
    )  # fmt: skip
    from benchmark.leaderboard.submission import software_differences
    from benchmark.leaderboard.validate import NoDetectionsWarning

    try:
        check_leaderboard_dir(leaderboard, "--leaderboard")
        if check is not None:
            if results_dir is not None or name is not None:
                fail("--check FILE takes no RESULTS_DIR or --name")
            lb = leaderboard if leaderboard.is_dir() else None
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", NoDetectionsWarning)
                data = check_submission_file(check, leaderboard_dir=lb, detections=detections or [], groundtruth=groundtruth)
            conditions = ", ".join(sorted(data["conditions"]))
            shipped = [c for c, v in data["conditions"].items() if v.get("shipped_detections_sha256")]
            recomputed = (f"; AP recomputed from its shipped detections ({len(shipped)} condition(s))" if shipped else "")
            recomputed += f"; AP recomputed from {len(detections)} detections file(s)" if detections else ""
            typer.echo(f"ok: {check.name} (protocol {data['collection']['protocol']}, conditions {conditions}{recomputed})")
            for warning in caught:
                if issubclass(warning.category, NoDetectionsWarning):
                    typer.echo(f"warning: {warning.message}", err=True)
            differences = software_differences(data)
            if differences:  # a reproduction here need not give the same bytes (docs/performance.md)
                typer.echo(f"warning: {check.name} was {' and '.join(differences)}: a rerun here may give "
                           "other bytes (AP within about 0.015 per distance)", err=True)
            return
        if results_dir is None or name is None:
            fail("give RESULTS_DIR and --name (or --check FILE)")
        if detections or groundtruth:
            fail("--detections/--groundtruth go with --check; a run folder's own detections.json is always verified")
        groups = group_by_camera(find_runs(results_dir))
        if camera is not None:
            if camera not in groups:
                fail(f"camera {camera!r} is not in {results_dir} (cameras: {', '.join(groups)}){did_you_mean(camera, groups)}")
            groups = {camera: groups[camera]}
        if len(groups) > 1 and "{camera}" not in name:
            fail(f"{results_dir} holds {len(groups)} cameras ({', '.join(groups)}): put {{camera}} in --name or choose one with --camera")
        protocols = load_protocols(leaderboard)
        subs = [build_submission(runs, name=name.replace("{camera}", cam), submitter=submitter, created_at=created_at,
                                 n_resamples=n_resamples, seed=seed, measure_mtf=mtf, protocols=protocols)
                for cam, runs in groups.items()]  # fmt: skip
        for sub in subs:  # all checked before any is written
            check_not_duplicate(sub, leaderboard)
        for sub in subs:
            path = write_submission(sub, leaderboard)
            day = _od50_text(sub["conditions"]["day"])
            skipped = sorted({r.condition for r in groups[sub["camera"]["name"]]} - set(sub["conditions"]))
            note = f"; not ranked, left out: {', '.join(skipped)}" if skipped else ""
            typer.echo(f"wrote {path} (day OD50 {day}, {n_resamples} bootstrap resamples; conditions {', '.join(sorted(sub['conditions']))}{note})")
    except (SubmissionError, ValueError) as exc:
        fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    except OSError as exc:  # the leaderboard folder unwritable, disk full: one line
        fail(f"cannot write into {leaderboard}: {exc.strerror or type(exc).__name__}")


def check_leaderboard_dir(folder: Path, what: str) -> Path:
    """A leaderboard folder to read or write: a folder (or none yet), not a collection,
    run or sweep folder nor inside one (ValueError, one line)."""
    from metricscenes.outputs import LEADERBOARD, check_output

    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{what} {folder} is a file, not a leaderboard folder (one that holds submissions/)")
    return check_output(folder, what, own=LEADERBOARD)


def _od50_text(cond: dict) -> str:
    """Day OD50 for the submit line: the bound when censored ("> 200 m"), else "123.4 m"."""
    from benchmark.leaderboard.render import censoring

    censored, bound, _ = censoring(cond)
    if censored and bound is not None:
        return f"{censored} {bound:g} m"
    return "inf" if cond["od50_m"] is None else f"{cond['od50_m']:.1f} m"


def leaderboard_cmd(
    dir: Annotated[Path, typer.Option("--dir", help="leaderboard folder (holds submissions/)")] = Path("leaderboard"),
) -> None:
    """Render README.md and index.html from the leaderboard's submissions/."""
    from benchmark.leaderboard import render_leaderboard

    if not dir.is_dir():
        fail(f"{dir}: no such leaderboard folder")
    try:
        check_leaderboard_dir(dir, "--dir")
    except ValueError as exc:
        fail(str(exc))
    try:
        readme, page = render_leaderboard(dir)
    except (SubmissionError, ValueError) as exc:
        fail(f"{str(exc).splitlines()[0]} (the table was not changed)")
    except OSError as exc:
        fail(f"cannot write into {dir}: {exc.strerror or type(exc).__name__} (the table was not changed)")
    typer.echo(f"wrote {readme} and {page}")


SCHEMAS = ("submission",)


def schema(which: Annotated[str, typer.Argument(help="which schema: submission")] = "submission") -> None:
    """Print a JSON Schema shipped with the package."""
    from benchmark.leaderboard import schema_text

    if which not in SCHEMAS:
        fail(f"unknown schema {which!r} (known: {', '.join(SCHEMAS)})")
    typer.echo(schema_text(), nl=False)


def register(app: typer.Typer) -> None:
    """Add ``submit``, ``leaderboard`` and ``schema`` to the ``benchmark`` app."""
    app.command("submit")(submit)
    app.command("leaderboard")(leaderboard_cmd)
    app.command("schema")(schema)
