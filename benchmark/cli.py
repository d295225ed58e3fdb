"""``benchmark`` command line: cameras, detect, run (and more as they land)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn
from rich.table import Table

from benchmark.cli_cameras import app as cameras_app
from benchmark import cli_detect, cli_leaderboard

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_show_locals=False,
                  help="How well does a camera let a detector see cars? Simulate, detect, score.")
app.add_typer(cameras_app, name="cameras", help="The camera registry: list, show, measure MTF50.")
cli_detect.register(app)
cli_leaderboard.register(app)
console = Console()
err = Console(stderr=True)


def fail(message: str, code: int = 2) -> None:
    """One-line error, non-zero exit, no traceback."""
    err.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
    raise typer.Exit(code)


@app.command()
def run(
    camera: Annotated[str, typer.Option(help="registry name (cam01..cam13), number, or a camera YAML")],
    collection: Annotated[Path, typer.Option(help="collection folder written by `metricscenes generate`")],
    out: Annotated[Path, typer.Option("--out", "-o", help="results folder")],
    condition: Annotated[str, typer.Option(help="a condition of the collection (day, dusk, night)")] = "day",
    model: Annotated[str, typer.Option(help="detector: registry name or .onnx path")] = "yolov5n-dynamic",
    input_size: Annotated[str, typer.Option(
        help="native | multiscale (native + 640, the reference) | an integer such as 640")] = "multiscale",
    seed: Annotated[int, typer.Option(help="sensor noise seed")] = 0,
    threads: Annotated[Optional[int], typer.Option(min=1, help="detector threads")] = None,
    save_images: Annotated[bool, typer.Option(help="write the camera's sRGB images")] = True,
    backend: Annotated[str, typer.Option(help="faster-coco-eval | pycocotools")] = "faster-coco-eval",
) -> None:
    """Simulate one camera on a collection, detect cars, print AP per distance."""
    from benchmark.cameras import load_camera
    from benchmark.detectors import DetectorError, load_detector
    from benchmark.run import run_camera
    from metricscenes.store import Collection, CollectionError

    try:
        cam = load_camera(camera)
        col = Collection.open(collection)
        if condition not in col.condition_names:
            fail(f"unknown condition {condition!r} (this collection has: {', '.join(col.condition_names)})")
        detector = load_detector(model, input_size=input_size, threads=threads)
    except (ValueError, DetectorError, CollectionError) as exc:
        fail(str(exc).splitlines()[0])
    with Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                  TimeElapsedColumn(), TimeRemainingColumn(), console=err) as bar:
        task = bar.add_task(f"{cam.name} · {condition}", total=len(col.scenes()))
        results = run_camera(col, cam, condition, detector, out, seed=seed, save_images=save_images,
                             backend=backend, progress=lambda done, total: bar.update(task, completed=done))
    table = Table(title=f"{cam.name} ({cam.pixel_um} µm, f/{cam.f_number}) · {condition} · {detector.name}")
    for col_name in ("distance (m)", "AP", "AP50", "images"):
        table.add_column(col_name, justify="right")
    for row in results["per_distance"]:
        table.add_row(f"{row['distance_m']:g}", f"{row['ap']:.3f}", f"{row['ap50']:.3f}", str(row["n_images"]))
    console.print(table)
    od50 = results["od50_m"]
    console.print(f"OD50 = {od50:.1f} m" if od50 is not None else "OD50: undefined (AP never reaches 0.5)")
    console.print(f"wrote {out / 'results.json'}")


def main() -> None:
    app(prog_name="benchmark")


if __name__ == "__main__":
    sys.exit(main())
