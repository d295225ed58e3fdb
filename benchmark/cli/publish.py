"""``benchmark publish``: the tables of ``docs/data`` and the markdown of docs/results.md, made
from sweep folders and collections (:mod:`benchmark.publish`).

Mounted by the main CLI as ``app.add_typer(publish_app, name="publish")``. Each command writes
its CSV (``--out``) and prints the markdown the docs quote.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from benchmark.cli.help import HELP_SETTINGS
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES

app = typer.Typer(help="The tables of docs/data and docs/results.md, made from sweeps and collections.",
                  no_args_is_help=True, rich_markup_mode=None, context_settings=HELP_SETTINGS)

CSV_OUT = "CSV of the table"
RESAMPLES_HELP = "bootstrap resamples over environments"


def _names(text: str) -> list[str]:
    return [name for name in text.split(",") if name]


def _write_and_print(table, out: Path | None, text: str) -> None:
    """A paired-bootstrap table to ``out`` (CSV, 4 decimals, as docs/data keeps them) if given, and its report printed."""
    if out:
        table.to_csv(out, index=False, float_format="%.4f")
    print(text)


@app.command()
def sweeps(
    results: Annotated[Path, typer.Option(help="folder holding the sweep folders")] = Path("results"),
    collection: Annotated[str, typer.Option(help="the sweep folders' names begin with it")] = "quick",
    out: Annotated[Path, typer.Option("--out", "-o", help="docs/data, or a collection's folder in it")] = Path("docs/data"),
) -> None:
    """Copy the sweeps' sweep.csv and od50.csv into docs/data under the names the docs read."""
    from benchmark.publish.sweep_tables import publish

    publish(results, out, collection)


@app.command()
def markdown(
    data: Annotated[Path, typer.Option(help="a docs/data folder")] = Path("docs/data"),
    against: Annotated[Optional[Path], typer.Option(
        help="another collection's tables (docs/data: quick's), camera by camera")] = None,
    names: Annotated[str, typer.Option(help="the --against collection's name, then --data's")] = "quick,metric-300",
) -> None:
    """Print docs/results.md's tables, each under its ### heading."""
    from benchmark.publish.results_page import markdown as page

    print(page(data, against, tuple(names.split(","))))


@app.command("mtf50-groups")
def mtf50_groups(
    sweep: Annotated[Path, typer.Option(help="the reference sweep folder")],
    conditions: Annotated[str, typer.Option(help="comma list")] = "day,night",
    resamples: Annotated[int, typer.Option(min=2, help=RESAMPLES_HELP)] = BOOTSTRAP_RESAMPLES,
    seed: Annotated[int, typer.Option(help="bootstrap seed")] = 0,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help=CSV_OUT)] = None,
) -> None:
    """Every pair of cameras of one published MTF50 group, paired bootstrap per condition."""
    from benchmark.publish.mtf50_groups import compare_groups, report

    table, lines = compare_groups(sweep, _names(conditions), resamples, seed)
    _write_and_print(table, out, report(table, lines))


@app.command("camera-variants")
def camera_variants(
    reference: Annotated[Path, typer.Option(help="sweep folder holding the reference camera's runs")],
    variants: Annotated[Path, typer.Option(help="sweep folder holding the variants' runs")],
    cameras: Annotated[str, typer.Option(help="comma list of the variants' camera names")],
    conditions: Annotated[str, typer.Option(help="comma list")] = "day,night",
    against: Annotated[str, typer.Option(help="the reference camera")] = "cam12",
    resamples: Annotated[int, typer.Option(min=2, help=RESAMPLES_HELP)] = BOOTSTRAP_RESAMPLES,
    seed: Annotated[int, typer.Option(help="bootstrap seed")] = 0,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help=CSV_OUT)] = None,
) -> None:
    """Each variant of a camera against the camera, paired bootstrap per condition."""
    from benchmark.publish.camera_variants import compare_variants, report

    table, lines = compare_variants(reference, variants, _names(cameras), _names(conditions), against, resamples, seed)
    _write_and_print(table, out, report(table, lines, against))


@app.command("backend-scores")
def backend_scores(
    cpu: Annotated[Path, typer.Option(help="sweep folder on the CPU's collection (B)")],
    gpu: Annotated[Path, typer.Option(help="sweep folder on the GPU's collection (A)")],
    conditions: Annotated[str, typer.Option(help="comma list")] = "day",
    resamples: Annotated[int, typer.Option(min=2, help=RESAMPLES_HELP)] = BOOTSTRAP_RESAMPLES,
    seed: Annotated[int, typer.Option(help="bootstrap seed")] = 0,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help=CSV_OUT)] = None,
) -> None:
    """Each camera's GPU-rendered run against its CPU-rendered run, paired bootstrap per condition."""
    import pandas as pd

    from benchmark.publish.backend_scores import HEADER, compare_backends

    rows, lines = [], []
    for condition in _names(conditions):
        more_rows, more_lines = compare_backends(gpu, cpu, condition, resamples, seed)
        rows += more_rows
        lines += more_lines
    _write_and_print(pd.DataFrame(rows), out, "\n".join([HEADER, *lines]))


@app.command("mtf50-isp")
def mtf50_isp(
    cameras: Annotated[str, typer.Option(help="comma list of registry cameras with a published MTF50 group")] = "all",
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help=CSV_OUT)] = None,
) -> None:
    """MTF50 on ISETCam's terms: its curve, and our e-SFR with the project's ISP, ISETCam's ISP, and both of ISETCam's."""
    from benchmark.camera import list_cameras, load_camera
    from benchmark.publish.mtf50_isp import markdown, mtf50_isp_table
    from metricscenes.cli_support import fail

    try:
        table = mtf50_isp_table(list_cameras() if cameras == "all" else [load_camera(n) for n in _names(cameras)])
    except ValueError as exc:
        fail(str(exc).splitlines()[0])
    if out:
        table.to_csv(out, index=False)
    print(markdown(table))


@app.command("night-exposure")
def night_exposure(
    collection: Annotated[Path, typer.Option(help="collection folder")],
    out: Annotated[Path, typer.Option("--out", "-o", help=CSV_OUT)],
    cameras: Annotated[str, typer.Option(help="comma list of registry names or YAMLs")] = "cam12",
    condition: Annotated[str, typer.Option(help="a condition of the collection")] = "night",
    exposure: Annotated[Optional[str], typer.Option(
        help="an acquisition policy for every camera, as `benchmark run --exposure`")] = None,
    histograms: Annotated[Optional[Path], typer.Option(
        help="also draw central-region histograms of --scenes for the first camera (PNG)")] = None,
    scenes: Annotated[str, typer.Option(help="comma list, for --histograms")] = (
        "env000-d025m,env000-d100m,env001-d025m,env001-d100m"),
) -> None:
    """Exposure time, electrons on the car and what sets the exposure, scene by scene."""
    from benchmark.camera import load_camera
    from benchmark.publish.night_exposure import central_histograms, night_exposure as rows_of, write_rows
    from metricscenes.store import Collection

    opened = Collection.open(collection)
    names = _names(cameras)
    if histograms:
        central_histograms(opened, load_camera(names[0]), condition, _names(scenes), histograms)
    write_rows(rows_of(opened, names, condition, exposure), out)
    print(f"wrote {out}")


@app.command("night-factors")
def night_factors(
    collection: Annotated[Path, typer.Option(help="collection folder")],
    out: Annotated[Path, typer.Option("--out", "-o", help=CSV_OUT)],
    cameras: Annotated[str, typer.Option(help="comma list of registry names or YAMLs")] = (
        "cameras/lux-sweep-1.4um-f2.4.yaml,cam12"),
    condition: Annotated[str, typer.Option(help="a targeted condition of the collection")] = "night",
    distances: Annotated[str, typer.Option(help="metres, as `benchmark run --distances`")] = "25,50,100",
    seed: Annotated[int, typer.Option(help="sensor noise seed")] = 0,
) -> None:
    """Our night against the paper's, one scene or camera change at a time, each row scored like a run."""
    from benchmark.detectors import load_detector
    from benchmark.publish.night_exposure import write_rows
    from benchmark.publish.night_factors import night_factors as rows_of
    from metricscenes.store import Collection

    rows = rows_of(Collection.open(collection), _names(cameras), load_detector("yolov5n-dynamic"), condition,
                   distances, seed, say=lambda line: print(line, flush=True))
    write_rows(rows, out)
    print(f"wrote {out}")
