"""``benchmark`` command line: cameras, detect, run (and more as they land)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.table import Table

from benchmark.cli.cameras import app as cameras_app
from benchmark.cli.help import HELP_SETTINGS
from benchmark.cli.publish import app as publish_app
from benchmark.detectors.policy import DEFAULT_INPUT_SIZE
from benchmark.cli import detect as cli_detect, leaderboard as cli_leaderboard
from benchmark.experiments import compare, paper_factors
from benchmark.leaderboard.protocols import condition_label
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES
from benchmark.scoring.detectability import FOUND_IOU, FOUND_SCORE
from benchmark.suggest import did_you_mean
from metricscenes.cli_support import SCHEDULER_HELP, cannot_write, fail, progress_bar

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_show_locals=False,
                  rich_markup_mode=None, context_settings=HELP_SETTINGS,  # help over the terminal's width
                  help="How well does a camera let a detector see cars? Simulate, detect, score.")
app.add_typer(cameras_app, name="cameras", help="The camera registry: list, show, measure MTF50.")
app.add_typer(publish_app, name="publish", help="The tables of docs/data and docs/results.md, made from sweeps and collections.")
cli_detect.register(app)
cli_leaderboard.register(app)
compare.register(app)
paper_factors.register(app)
console = Console()
err = Console(stderr=True)
EXPOSURE_HELP = ("exposure policy for every camera, replacing the camera's own: auto_peak (the paper's), mean_level, "
                 "percentile:P, hdr[:RATIO], fixed:SECONDS, each but fixed with an optional @LEVEL (docs/camera.md)")


SUBSET_ENV_HELP = "a quick try on some environments only: ids and ranges such as 0-2,5 (marked as a subset run)"
SUBSET_DIST_HELP = "a quick try at some distances only, in metres: 25,50 (marked as a subset run)"
CLASS_MAP_HELP = ("for a detector whose classes are not COCO's 80: the COCO class of each model class, in order "
                  "('car' for a single-class car detector, 'person,-,car'; '-' drops one; docs/detection.md)")
MODEL_DIR_HELP = "folder holding the registry's model files (default: $METRICSCENES_MODEL_DIR)"


def unknown_condition(condition: str, known) -> str:
    """The one-line refusal of a condition the collection lacks, with a "did you mean" (never taken silently)."""
    known = list(known)
    return f"unknown condition {condition!r} (this collection has: {', '.join(known)}){did_you_mean(condition, known)}"


def check_condition(collection, condition: str) -> None:
    """Refuse, in one line and before any work, a condition the collection lacks, or one whose
    light groups it does not hold (rendered with `generate --conditions`: the line says how to
    add them; :meth:`metricscenes.store.Collection.check_condition`)."""
    if condition not in collection.condition_names:
        fail(unknown_condition(condition, collection.condition_names))
    collection.check_condition(condition)


def camera_text(camera: dict) -> str:
    """MTF50 in both units, focal length and field of view of a results.json ``camera`` ("" for
    a record without them)."""
    if camera.get("focal_length_mm") is None or camera.get("mtf50_cy_per_mrad") is None:
        return ""
    fov = camera.get("fov_deg") or []
    where = f"focal length {camera['focal_length_mm']:g} mm" + (", field of view {:.1f}° x {:.1f}°".format(*fov) if fov else "")
    return (f"MTF50 {camera['mtf50_cy_per_mm']:.1f} cy/mm on the sensor = {camera['mtf50_cy_per_mrad']:.3f} cy/mrad in "
            f"object space ({where}; {camera.get('mtf50_source')})")


def subset_text(subset: dict) -> str:
    envs = ",".join(map(str, subset["environments"]))
    dists = ",".join(f"{d:g}" for d in subset["distances_m"])
    return f"subset run (environments {envs}; distances {dists} m): a quick try, not a full run — `benchmark submit` refuses it"


@app.command()
def run(
    camera: Annotated[str, typer.Option(help="registry name (cam01..cam13), number, or a camera YAML")],
    collection: Annotated[Path, typer.Option(help="collection folder written by `metricscenes generate`")],
    out: Annotated[Path, typer.Option("--out", "-o", help="results folder")],
    condition: Annotated[str, typer.Option(help="a condition of the collection (day, dusk, night)")] = "day",
    model: Annotated[str, typer.Option(help="detector: registry name or .onnx path")] = "yolov5n-dynamic",
    input_size: Annotated[str, typer.Option(
        help="native | multiscale (native + 640, the reference) | an integer such as 640")] = DEFAULT_INPUT_SIZE,
    seed: Annotated[int, typer.Option(help="sensor noise seed")] = 0,
    threads: Annotated[Optional[int], typer.Option(min=1, help="detector threads")] = None,
    save_images: Annotated[bool, typer.Option(help="write the camera's sRGB images")] = True,
    backend: Annotated[str, typer.Option(help="faster-coco-eval | pycocotools")] = "faster-coco-eval",
    exposure: Annotated[Optional[str], typer.Option(help=EXPOSURE_HELP)] = None,
    environments: Annotated[Optional[str], typer.Option(help=SUBSET_ENV_HELP)] = None,
    distances: Annotated[Optional[str], typer.Option(help=SUBSET_DIST_HELP)] = None,
    class_map: Annotated[Optional[str], typer.Option(help=CLASS_MAP_HELP)] = None,
    model_dir: Annotated[Optional[Path], typer.Option(help=MODEL_DIR_HELP)] = None,
) -> None:
    """Simulate one camera on a collection, detect cars, print AP per distance."""
    from benchmark.camera import load_camera
    from benchmark.detectors import DetectorError, load_detector
    from benchmark.camera.exposure import check_exposure_override, format_exposure, parse_exposure, with_exposure
    from benchmark.experiments.run import check_out_dir, run_camera
    from benchmark.experiments.subset import subset_collection
    from benchmark.experiments.run_folder import check_run_folder
    from metricscenes.outputs import RUN, check_output
    from metricscenes.store import Collection, CollectionError

    try:
        check_out_dir(out)
        check_output(out, "--out", own=RUN)  # a new folder or an earlier run's, never a sweep's or the leaderboard
        check_run_folder(out)  # nor a folder of other files
        policy = parse_exposure(exposure) if exposure is not None else None
        cam = load_camera(camera)
        check_exposure_override(cam, policy)  # before anything runs (the capture would refuse it mid-run)
        cam = with_exposure(cam, policy)
        col = subset_collection(Collection.open(collection), environments, distances)
        check_condition(col, condition)
        detector = load_detector(model, input_size=input_size, threads=threads, class_map=class_map, model_dir=model_dir)
    except (ValueError, DetectorError, CollectionError) as exc:
        fail(str(exc).splitlines()[0])
    try:  # a damaged array or a broken model is found on the way: nothing is written (run_camera stages)
        with progress_bar(err) as bar:
            task = bar.add_task(f"{cam.name} · {condition}", total=len(col.scenes()))
            results = run_camera(col, cam, condition, detector, out, seed=seed, save_images=save_images,
                                 backend=backend, progress=lambda done, total: bar.update(task, completed=done))
    except (ValueError, CollectionError) as exc:
        fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    except OSError as exc:  # a full disk, an unwritable folder: nothing written (run_camera stages)
        fail(cannot_write(out, exc))
    title = f"{cam.name} ({cam.pixel_um} µm, f/{cam.f_number}) · {condition_label(condition)} · {detector.name}"
    if policy is not None:
        title += f" · exposure {format_exposure(policy)}"
    table = Table(title=title, caption=WORKING_POINT_CAPTION)
    for col_name in ("distance (m)", "AP", "AP50", "images", "miss rate", "FP/image"):
        table.add_column(col_name, justify="right")
    for row in results.per_distance:
        table.add_row(f"{row.distance_m:g}", f"{row.ap:.3f}", f"{row.ap50:.3f}", str(row.n_images),
                      _rate(row.miss_rate), _rate(row.false_positives_per_image))
    console.print(table)
    console.print(od50_text(*results.ap_curve()))
    if camera_text(results.camera.model_dump()):
        console.print(camera_text(results.camera.model_dump()), highlight=False)
    if results.subset:
        console.print(subset_text(results.subset.model_dump()))
    console.print(f"wrote {out / 'results.json'}")


def parse_also_input_sizes(values: list[str]) -> dict:
    """``--also-input-size SIZE=FOLDER`` values as {input size: folder}; ValueError (one line)
    for a value without '=', a size that is no input size, or a size given twice."""
    from benchmark.detectors.policy import parse_input_size

    out: dict = {}
    for value in values:
        size, sep, folder = value.partition("=")
        if not sep or not size.strip() or not folder.strip():
            raise ValueError(f"--also-input-size {value!r}: expected SIZE=FOLDER, e.g. 640=results/quick-640")
        size = parse_input_size(size.strip())
        if size in out:
            raise ValueError(f"--also-input-size: input size {size} given twice")
        out[size] = Path(folder.strip())
    return out


@app.command()
def sweep(
    collection: Annotated[Path, typer.Option(help="collection folder written by `metricscenes generate`")],
    out: Annotated[Path, typer.Option("--out", "-o", help="sweep folder (runs are cached and reused there)")],
    cameras: Annotated[str, typer.Option(help="'all' or a comma list: cam01,cam05 (names, numbers or YAML paths)")] = "all",
    conditions: Annotated[str, typer.Option(help="comma list of the collection's conditions")] = "day,night",
    model: Annotated[str, typer.Option(help="detector: registry name or .onnx path")] = "yolov5n-dynamic",
    input_size: Annotated[str, typer.Option(
        help="native | multiscale (native + 640, the reference) | an integer such as 640")] = DEFAULT_INPUT_SIZE,
    resamples: Annotated[int, typer.Option(min=2, help="bootstrap resamples of OD50 (over environments)")] = BOOTSTRAP_RESAMPLES,
    seed: Annotated[int, typer.Option(help="sensor noise and bootstrap seed")] = 0,
    mtf_source: Annotated[str, typer.Option(help="MTF50 of each camera: measured | analytic | published_group (falling back in that order)")] = "measured",
    threads: Annotated[Optional[int], typer.Option(min=1, help="detector threads")] = None,
    save_images: Annotated[bool, typer.Option(help="write the cameras' sRGB images (for the report's strips)")] = True,
    exposure: Annotated[Optional[str], typer.Option(help=EXPOSURE_HELP)] = None,
    environments: Annotated[Optional[str], typer.Option(help=SUBSET_ENV_HELP)] = None,
    distances: Annotated[Optional[str], typer.Option(help=SUBSET_DIST_HELP)] = None,
    class_map: Annotated[Optional[str], typer.Option(help=CLASS_MAP_HELP)] = None,
    workers: Annotated[int, typer.Option(min=1, help="processes running camera × condition runs in parallel")] = 1,
    scheduler: Annotated[Optional[str], typer.Option(help=SCHEDULER_HELP)] = None,
    captures_from: Annotated[Optional[Path], typer.Option(
        help="another sweep folder on this collection: detect on its runs' camera images where they match "
             "(same camera, condition and seed) instead of simulating the camera again")] = None,
    also_input_size: Annotated[Optional[list[str]], typer.Option(
        help="SIZE=FOLDER (repeatable): also write the sweep of input size SIZE, one of the detector's passes "
             "(native or 640 with multiscale), into FOLDER, from the same captures and inference")] = None,
    model_dir: Annotated[Optional[Path], typer.Option(help=MODEL_DIR_HELP)] = None,
) -> None:
    """Every camera × condition on a collection: AP table (sweep.csv), OD50 ± SD (od50.csv)."""
    from benchmark.experiments import sweep as sweep_module
    from benchmark.camera import camera_names, load_camera
    from benchmark.detectors import DetectorError, load_detector
    from benchmark.camera.exposure import format_exposure, parse_exposure
    from benchmark.experiments.run import check_out_dir, check_pass_policies
    from benchmark.experiments.subset import subset_collection
    from metricscenes.backends import BackendError, runs_in_process, threads_per_unit
    from metricscenes.outputs import SWEEP, check_output
    from metricscenes.store import Collection, CollectionError

    try:
        check_out_dir(out)
        check_output(out, "--out", own=SWEEP)  # a new folder or an earlier sweep's
        policy = parse_exposure(exposure) if exposure is not None else None
        names = camera_names() if cameras.strip().lower() == "all" else [c.strip() for c in cameras.split(",") if c.strip()]
        cams = [load_camera(name) for name in names]
        col = subset_collection(Collection.open(collection), environments, distances)
        conds = [c.strip() for c in conditions.split(",") if c.strip()]
        for condition in conds:
            check_condition(col, condition)
        if mtf_source not in sweep_module.MTF50_SOURCES:
            fail(f"--mtf-source must be one of {', '.join(sweep_module.MTF50_SOURCES)}, got {mtf_source!r}")
        if not runs_in_process(workers, scheduler):  # each worker loads the detector again, with its share of the CPUs
            threads = threads_per_unit(threads, workers, scheduler)
        detector = load_detector(model, input_size=input_size, threads=threads, class_map=class_map, model_dir=model_dir)
        also = parse_also_input_sizes(also_input_size or [])
        check_pass_policies(detector, also)
        for folder in also.values():
            check_out_dir(folder, "--also-input-size")
            check_output(folder, "--also-input-size", own=SWEEP)
    except (ValueError, DetectorError, CollectionError) as exc:
        fail(str(exc).splitlines()[0])
    if not cams or not conds:
        fail("--cameras and --conditions must each name at least one")
    try:
        with progress_bar(err) as bar:
            task = bar.add_task("sweep", total=None)

            def progress(done: int, total: int, label: str) -> None:
                bar.update(task, completed=done, total=total, description=label)

            sweep_module.sweep(col, cams, conds, detector, out, seed=seed, n_resamples=resamples,
                               progress=progress, mtf_source=mtf_source, save_images=save_images, exposure=policy,
                               workers=workers, scheduler=scheduler, captures_from=captures_from, also=also)
    except (ValueError, DetectorError, CollectionError, BackendError) as exc:
        fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    except OSError as exc:  # a full disk, an unwritable folder: the runs finished so far are kept
        fail(cannot_write(out, exc))
    _, od50_table = sweep_module.load_sweep(out)
    title = (f"OD50 ± SD (m) · {detector.name} · {resamples} bootstrap resamples over environments; MTF50 in cy/mm "
             "on the sensor and cy/mrad in object space (f: focal length, mm)")
    if policy is not None:
        title += f" · exposure {format_exposure(policy)}"
    table = Table(title=title)
    table.add_column("camera")
    table.add_column("MTF50 (cy/mm)", justify="right", no_wrap=True)
    table.add_column("cy/mrad (f)", justify="right", no_wrap=True)
    for condition in conds:  # named by what it physically is (protocols.yaml labels)
        table.add_column(condition_label(condition), justify="right")
    ranges = Table(title="AP range ± SD (m): area under AP vs distance, defined where OD50 is censored (docs/scoring.md)")
    ranges.add_column("camera")
    for condition in conds:
        ranges.add_column(condition_label(condition), justify="right")
    for camera_name, rows in od50_table.groupby("camera", sort=False):
        by_condition = rows.set_index("condition")
        cells = [sweep_module.od50_cell(by_condition.loc[condition]) for condition in conds]
        mtf, mrad = rows["mtf50_cy_per_mm"].iloc[0], rows["mtf50_cy_per_mrad"].iloc[0]
        table.add_row(camera_name, f"{mtf:.1f} ({rows['mtf50_source'].iloc[0]})",
                      f"{mrad:.3f} ({rows['focal_length_mm'].iloc[0]:g})", *cells)
        ranges.add_row(camera_name, *(sweep_module.ap_range_cell(by_condition.loc[condition]) for condition in conds))
    console.print(table)
    console.print(ranges)
    from benchmark.scoring import few_footnote, too_few

    if any(map(too_few, od50_table["n_environments"])):
        console.print(few_footnote(), highlight=False)
    if getattr(col, "subset", None):
        console.print(subset_text(col.subset))
    console.print(f"wrote {out / 'sweep.csv'}, {out / 'od50.csv'}")


@app.command()
def report(
    results_dirs: Annotated[list[Path], typer.Argument(
        help="`benchmark sweep` or `benchmark run` folders, one or several (of one collection and detector)",
        metavar="RESULTS_DIR")],
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help=(
        "HTML page (default RESULTS_DIR/report.html for one folder; required for several)"))] = None,
    references: Annotated[Optional[str], typer.Option(help=(
        "a leaderboard protocol (quick, metric-300): draw the runs' AP vs distance over its reference submissions' band"))] = None,
    leaderboard: Annotated[Path, typer.Option("--leaderboard", help="leaderboard folder --references reads")] = Path("leaderboard"),
) -> None:
    """One self-contained HTML page: AP curves, SPMs, OD50 vs MTF50, table, image strips (of one folder, or of
    several run and sweep folders side by side); with --references, the runs over the references' band."""
    from benchmark.experiments.report import report as write_report
    from metricscenes.outputs import RUN, SWEEP, check_output, folder_kind

    for results_dir in results_dirs:
        if not results_dir.is_dir():
            fail(f"results folder not found: {results_dir}")
        if folder_kind(results_dir) not in (RUN, SWEEP):
            fail(f"{results_dir} is neither a sweep folder (sweep.csv) nor a run folder (results.json)")
    if out is None and len(results_dirs) > 1:
        fail(f"{len(results_dirs)} results folders: name the page with --out (e.g. --out reports/mine.html)")
    if out is not None and (out.suffix.lower() != ".html" or out.is_dir()):
        fail(f"--out {out}: the report is an HTML page; name a file ending in .html")
    given = results_dirs[0] if len(results_dirs) == 1 else None  # several: the page goes outside all of them
    try:  # the page, figures/ and report_table.csv: in RESULTS_DIR, or outside every collection, run and leaderboard
        check_output(out if out is not None else results_dirs[0] / "report.html", "--out", given=given)
        with err.status("writing the report"):
            page = write_report(results_dirs if len(results_dirs) > 1 else results_dirs[0], out, references=references,
                                leaderboard_dir=leaderboard)
    except (ValueError, OSError, KeyError) as exc:
        fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
    console.print(f"wrote {page} (figures in {page.parent / 'figures'})")


@app.command()
def score(
    results_dir: Annotated[Path, typer.Argument(help="a `benchmark run` folder")],
    backend: Annotated[str, typer.Option(help="faster-coco-eval | pycocotools")] = "faster-coco-eval",
    score_threshold: Annotated[float, typer.Option(min=0.0, max=1.0, help="working threshold for detection rates")] = FOUND_SCORE,
    iou: Annotated[float, typer.Option(min=0.0, max=1.0, help="IoU that counts as finding the car")] = FOUND_IOU,
    as_json: Annotated[bool, typer.Option("--json")] = False,
) -> None:
    """Re-score a run from its detections: AP per distance, detection rates, what the car was taken for."""
    import json

    from benchmark.scoring import ap_by_distance, detection_rates, od50

    try:
        groundtruth = json.loads((results_dir / "groundtruth.json").read_text())
        detections = json.loads((results_dir / "detections.json").read_text())
        ap_rows = ap_by_distance(groundtruth, detections, backend=backend)
    except FileNotFoundError as exc:
        fail(f"{results_dir}: not a run folder ({Path(exc.filename).name} is missing)")
    except (json.JSONDecodeError, ValueError, KeyError) as exc:
        fail(f"{results_dir}: cannot score ({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})")
    rates = detection_rates(groundtruth, detections, score_threshold=score_threshold, iou_threshold=iou)
    rows = [{**a, **{k: r[k] for k in ("rate", "detected", "miss_rate", "false_positives_per_image", "mistaken_for",
                                        "missed_scenes")}}
            for a, r in zip(ap_rows, rates, strict=True)]
    distance_od50 = od50([r["distance_m"] for r in rows], [r["ap"] for r in rows])
    if as_json:
        print(json.dumps({"backend": backend, "score_threshold": score_threshold, "iou_threshold": iou,
                          "od50_m": distance_od50 if distance_od50 != float("inf") else None,
                          "per_distance": rows}, indent=1))
        return
    table = Table(title=f"{results_dir} · {backend}")
    for col in ("distance (m)", "AP", "AP50", f"found (score ≥ {score_threshold:g})", "miss rate", "FP/image", "taken for"):
        table.add_column(col, justify="right")
    for r in rows:
        taken = ", ".join(f"{k} {v}" for k, v in r["mistaken_for"].items())
        table.add_row(f"{r['distance_m']:g}", f"{r['ap']:.3f}", f"{r['ap50']:.3f}",
                      f"{r['detected']}/{r['n_images']}", _rate(r["miss_rate"]), _rate(r["false_positives_per_image"]), taken)
    console.print(table)
    console.print(od50_text([r["distance_m"] for r in rows], [r["ap"] for r in rows]))


WORKING_POINT_CAPTION = (f"miss rate and FP/image at the working threshold: a car detection of score ≥ {FOUND_SCORE:g} "
                         f"on the car at IoU ≥ {FOUND_IOU:g} finds it; FP/image: car detections at that score that do "
                         "not (docs/scoring.md)")


def _rate(value: float | None) -> str:
    return "–" if value is None else f"{value:.2f}"


def od50_text(distances_m: list[float], ap: list[float]) -> str:
    """OD50 for people, read off the AP curve: a bound where AP does not cross 0.5 inside the
    measured distances ("OD50 > 200 m", "OD50 < 25 m"), never an extrapolated number."""
    from benchmark.scoring.od50 import format_od50, od50, od50_censoring

    censored, bound_m = od50_censoring(distances_m, ap)
    return "OD50 " + format_od50(od50(distances_m, ap), censored, bound_m)


def main() -> None:
    app(prog_name="benchmark")


if __name__ == "__main__":
    sys.exit(main())
