"""``metricscenes`` command line: generate, verify, info, preview, export, preview-assets."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.console import Console
from rich.table import Table

from metricscenes import __version__
from metricscenes.cli_support import SCHEDULER_HELP, cannot_write, fail, progress_bar

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_show_locals=False,
                  help="Seeded metric driving scenes rendered as spectral radiance (W·sr⁻¹·m⁻²·nm⁻¹).")
console = Console()
err = Console(stderr=True)


def _user_errors():
    from metricscenes.backends import BackendError
    from metricscenes.manifest import ManifestError
    from metricscenes.outputs import OutputError
    from metricscenes.render import RenderError
    from metricscenes.store import CollectionError

    return (ManifestError, CollectionError, RenderError, BackendError, OutputError)


@app.command()
def generate(
    manifest: Annotated[Path, typer.Option("--manifest", "-m", help="collection manifest (YAML)")],
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="collection folder to write")] = None,
    workers: Annotated[int, typer.Option(min=1, help="render processes")] = 1,
    threads: Annotated[Optional[int], typer.Option(min=1, help="render threads per process")] = None,
    scheduler: Annotated[Optional[str], typer.Option(help=SCHEDULER_HELP)] = None,
    conditions: Annotated[Optional[str], typer.Option(
        help="render only the light groups these conditions need: day,dusk (default: all; run again with more "
             "to add theirs)")] = None,
    light_groups: Annotated[Optional[str], typer.Option(
        "--light-groups", help="render only these light groups (and those --conditions need): sky_day,ego_lights")
    ] = None,
    dry_run: Annotated[bool, typer.Option("--dry-run", help="print the plan, render nothing")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="machine-readable output")] = False,
) -> None:
    """Render a collection (resumes an interrupted run; same manifest → same bytes)."""
    from metricscenes.generate import requested_light_groups
    from metricscenes.manifest import load_manifest
    from metricscenes.plan import plan_collection

    try:
        m = load_manifest(manifest)
        asked = requested_light_groups(m, _names(conditions), _names(light_groups))
        if dry_run:
            scenes = [s.summary() for s in plan_collection(m)]
            if as_json:
                print(json.dumps({"manifest": m.name, "manifest_sha256": m.sha256(), "scenes": scenes}, indent=1))
            else:
                _plan_table(scenes)
            return
        if out is None:
            fail("--out is required unless --dry-run")
        from metricscenes.generate import check_before_writing
        from metricscenes.generate import generate as run_generate
        from metricscenes.outputs import COLLECTION, check_output
        from metricscenes.store import Collection

        check_output(out, "--out", own=COLLECTION)  # not inside a run, sweep or leaderboard folder

        # Before any output: --out, --scheduler, the memory estimate, the variant (LLVM can abort
        # the process, CUDA needs a GPU). generate() checks them again (cheaply), then locks --out.
        check_before_writing(m, out, workers, scheduler)

        started = time.perf_counter()
        with progress_bar(err, disable=as_json) as bar:
            task = bar.add_task(f"rendering {m.name}", total=None)

            def progress(done: int, total: int, key: str | None) -> None:
                bar.update(task, completed=done, total=total, description=f"rendering {key or m.name}")

            run_generate(m, out, workers=workers, threads=threads, scheduler=scheduler, progress=progress,
                         notice=lambda line: err.print(line, highlight=False, soft_wrap=True), light_groups=asked)
        seconds = time.perf_counter() - started
        held = Collection.open(out).light_groups
        if as_json:
            print(json.dumps({"collection": str(out), "seconds": round(seconds, 2), "light_groups": list(held)}))
        else:
            more = (f"; it holds {', '.join(held)}: run again with more --conditions (or none: all) to add the others"
                    if held != m.light_groups else "")
            console.print(f"wrote {out} in {seconds:.1f} s{more}", highlight=False)
    except _user_errors() as exc:
        fail(str(exc))
    except OSError as exc:  # --out unwritable, disk full: one line, the lock released
        fail(cannot_write(out, exc))


def _names(text: str | None) -> tuple[str, ...]:
    """The names of a comma list (None: none)."""
    return tuple(name.strip() for name in (text or "").split(",") if name.strip())


def _plan_table(scenes: list[dict]) -> None:
    table = Table(title="plan")
    for col in ("scene_id", "distance_m", "car_id", "road_id", "heading", "sky_day_id", "sky_night_id"):
        table.add_column(col)
    for s in scenes:
        table.add_row(*(str(s[c]) for c in ("scene_id", "distance_m", "car_id", "road_id", "heading",
                                             "sky_day_id", "sky_night_id")))
    console.print(table)


@app.command()
def info(
    collection: Annotated[Path, typer.Argument(help="collection folder")],
    as_json: Annotated[bool, typer.Option("--json")] = False,
    photometry: Annotated[bool, typer.Option(
        "--photometry", help="per scene and condition: lux at the camera, image-plane lux at f/2.4")] = False,
    f_number: Annotated[float, typer.Option(
        "--f-number", min=0.51, max=63.9, help="with --photometry: the ideal lens of the image-plane lux, and the "
        "camera whose weights a target_at: camera condition shows (an ideal lens at this f-number over the "
        "collection's field; a run records its own camera's)")] = 2.4,
) -> None:
    """Summarise a collection."""
    from metricscenes.store import Collection

    try:
        c = Collection.open(collection)
    except _user_errors() as exc:
        fail(f"{exc}{_generating_now(collection)}")
    scenes = c.scenes()
    size = sum(p.stat().st_size for p in (collection / "radiance.zarr").rglob("*") if p.is_file())
    summary = {
        "name": c.name, "protocol": c.protocol, "manifest_sha256": c.manifest_sha256,
        "package_version": c.resolved.package_version,
        "render_variant": c.render_variant, "scenes": len(scenes),
        "environments": len({s.environment_id for s in scenes}),
        "distances_m": sorted({s.distance_m for s in scenes}), "conditions": c.condition_names,
        "light_groups": list(c.light_groups), "conditions_held": c.held_condition_names,
        "reference_grid_px": list(c.reference_grid), "arrays": len(c.resolved.arrays),
        "radiance_units": "W sr-1 m-2 nm-1", "wavelengths_nm": [400, 700, 10], "store_bytes": size,
    }
    if photometry:  # reads every scene's radiance: damage found on the way is one line
        try:
            summary["photometry"] = [c.photometry(s.scene_id, cond, f_number) for s in scenes
                                     for cond in c.held_condition_names]
        except _user_errors() as exc:
            fail(str(exc))
    if as_json:
        print(json.dumps(summary, indent=1))
        return
    rows = summary.pop("photometry", [])
    if rows:
        _photometry_table(rows, f_number)
    table = Table(title=f"collection {c.name}", show_header=False)
    for k, v in summary.items():
        table.add_row(k, str(v))
    console.print(table)
    if len(c.light_groups) < len(c.manifest.light_groups):
        console.print(f"holds {len(c.light_groups)} of its {len(c.manifest.light_groups)} light groups; add the others "
                      f"with: {c.generate_command()}", highlight=False, soft_wrap=True)


def _generating_now(collection: Path) -> str:
    """' (PID … on host … since … is generating it now: …)' where a live ``generate`` holds the
    collection's lock (what it lacks may just not be written yet), else ''."""
    from metricscenes.lock import describe, writer

    holder = writer(collection)
    return f" ({describe(holder)} is generating it now: wait for it)" if holder else ""


def _photometry_table(rows: list[dict], f_number: float = 2.4) -> None:
    """Mean over scenes, per condition."""
    table = Table(title="photometry (mean over scenes; --json: each scene, and a targeted condition's weights)")
    for col in ("condition", "lux at camera", "luminance cd/m²", f"image-plane lux f/{f_number:g}", "min-max",
                "over target"):
        table.add_column(col, justify="right")
    for cond in dict.fromkeys(r["condition"] for r in rows):
        sel = [r for r in rows if r["condition"] == cond]
        mean = {k: sum(r[k] for r in sel) / len(sel)
                for k in ("illuminance_at_camera_lux", "mean_luminance_cd_m2", "image_plane_illuminance_lux")}
        plane = [r["image_plane_illuminance_lux"] for r in sel]
        over = (f"{sum(r['targeted'].get('over_target', False) for r in sel)} of {len(sel)}"
                if "targeted" in sel[0] else "")
        table.add_row(cond, f"{mean['illuminance_at_camera_lux']:.4g}", f"{mean['mean_luminance_cd_m2']:.4g}",
                      f"{mean['image_plane_illuminance_lux']:.4g}", f"{min(plane):.3g}-{max(plane):.3g}", over)
    console.print(table)


@app.command()
def verify(collection: Annotated[Path, typer.Argument(help="collection folder")]) -> None:
    """Check the whole collection: resolved manifest, every array's sha256 (masks too) and its
    attributes', ground truth."""
    from metricscenes.store import upgrade_notes, verify_collection

    problems = verify_collection(collection)
    for line in problems:
        console.print(f"bad: {line}", highlight=False, soft_wrap=True)
    if problems:
        fail(f"{collection}: {len(problems)} problem(s); rerun `metricscenes generate` with its manifest to repair it"
             f"{_generating_now(collection)}", code=1)
    for line in upgrade_notes(collection):
        console.print(f"note: {collection}: {line}", highlight=False, soft_wrap=True)
    console.print("manifest, arrays, their attributes and ground truth match their records")


@app.command()
def preview(
    collection: Annotated[Path, typer.Argument(help="collection folder")],
    condition: Annotated[str, typer.Option(help="condition to show")] = "day",
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="PNG to write (default: preview-<collection>-<condition>.png here)")] = None,
    columns: Annotated[int, typer.Option(min=1)] = 6,
    white: Annotated[Optional[float], typer.Option(
        min=1e-12, help="luminance (cd/m²) drawn at 80 % of full scale, the same for every tile "
        "(to compare conditions); default: the 99th percentile of the whole sheet's luminance")] = None,
    per_tile: Annotated[bool, typer.Option("--per-tile", help="expose each tile for itself (a dark scene looks lit)")] = False,
) -> None:
    """Write an sRGB contact sheet of every scene (display rendering, not a camera): one
    exposure for the whole sheet, so night looks like night."""
    from metricscenes.outputs import check_file_output
    from metricscenes.photometry import radiance_to_xyz
    from metricscenes.preview import contact_sheet, white_luminance, xyz_to_srgb8
    from metricscenes.store import Collection

    def xyz(scene):  # at 2x the reference grid, so distant cars stay visible
        return radiance_to_xyz(c.radiance(scene.scene_id, condition).resample(width * 2, height * 2))

    try:
        c = Collection.open(collection)
        # Never into the collection (read-only): here by default; a PNG, checked before any work.
        out = check_file_output(out or Path(f"preview-{c.name}-{condition}.png"), "--out", (".png",))
        width, height = c.reference_grid
        scenes = c.scenes()
        sheet_white = white
        with progress_bar(err) as bar:
            if sheet_white is None and not per_tile:
                # Pass 1: the sheet's white from every 4th pixel of every tile (memory stays one tile).
                task = bar.add_task(f"metering {condition}", total=len(scenes))
                samples = []
                for s in scenes:
                    samples.append(xyz(s)[::2, ::2])
                    bar.advance(task)
                sheet_white = white_luminance(samples)
            task = bar.add_task(f"preview {condition}", total=len(scenes))
            tiles = []
            for s in scenes:
                tile = xyz(s)
                tiles.append(xyz_to_srgb8(tile, white_luminance([tile]) if per_tile else sheet_white))
                bar.advance(task)
    except _user_errors() as exc:
        fail(str(exc))
    labels = [f"{s.scene_id} {condition}" for s in scenes]
    path = contact_sheet(tiles, labels, columns, out)
    exposure = "each tile exposed for itself" if per_tile else f"white = {sheet_white:.4g} cd/m² for every tile"
    console.print(f"wrote {path} ({exposure})")


@app.command("export")
def export_cmd(
    collection: Annotated[Path, typer.Argument(help="collection folder")],
    out: Annotated[Path, typer.Argument(help="file to write (e.g. scene.h5)")],
    scene: Annotated[str, typer.Option("--scene", help="scene id, e.g. env000-d100m")],
    condition: Annotated[str, typer.Option(help="condition, e.g. day")] = "day",
    fmt: Annotated[str, typer.Option("--format", help="output format (hdf5: ISETCam-ready)")] = "hdf5",
    width_px: Annotated[Optional[int], typer.Option(
        "--width-px", help="export grid width (default: the inset's sampling over the field, at most 2688)")] = None,
    gzip: Annotated[bool, typer.Option("--gzip", help="gzip the cubes (~25 % smaller, ~4x slower)")] = False,
) -> None:
    """Export one scene's composited radiance and photons (with wave, fov, distance, box) for ISETCam."""
    from metricscenes.export import ExportError, export_scene
    from metricscenes.outputs import check_file_output

    try:
        check_file_output(out, "OUT", (".h5", ".hdf5"))  # never into a collection, a run or a leaderboard
        path = export_scene(collection, scene, condition, fmt, out, width_px=width_px, gzip=gzip)
    except (*_user_errors(), ExportError) as exc:
        fail(str(exc))
    console.print(f"wrote {path}")


@app.command("preview-assets")
def preview_assets_cmd(
    kind: Annotated[str, typer.Argument(help="cars or skies")],
    out: Annotated[Path, typer.Option("--out", "-o", help="PNG to write")],
    spp: Annotated[int, typer.Option(help="samples per pixel")] = 64,
    seed: Annotated[int, typer.Option(help="sampler seed (tile i uses seed + i)")] = 0,
    workers: Annotated[int, typer.Option(min=1, help="render processes")] = 1,
    ids: Annotated[Optional[str], typer.Option(help="comma-separated asset ids (default: all)")] = None,
    columns: Annotated[int, typer.Option(min=1)] = 10,
) -> None:
    """Render a labelled contact sheet of the 50 library cars or the 30 skies (docs/img/)."""
    from metricscenes.outputs import check_file_output
    from metricscenes.preview_assets import AssetPreviewError, asset_contact_sheet

    try:
        check_file_output(out, "--out", (".png",))  # before rendering anything
        chosen = None
        if ids is not None:
            try:
                chosen = [int(i) for i in ids.split(",") if i.strip()]
            except ValueError:
                raise AssetPreviewError(f"--ids must be comma-separated integers, got {ids!r}") from None
        path = asset_contact_sheet(kind, out, ids=chosen, spp=spp, seed=seed, workers=workers, columns=columns)
    except (*_user_errors(), AssetPreviewError) as exc:
        fail(str(exc))
    console.print(f"wrote {path}")


assets_app = typer.Typer(add_completion=False, no_args_is_help=True, help="The procedural asset library.")
app.add_typer(assets_app, name="assets")


@assets_app.command("list")
def assets_list(as_json: Annotated[bool, typer.Option("--json")] = False) -> None:
    """List the cars, roads and skies with their main parameters."""
    from dataclasses import asdict

    from metricscenes.assets import cars, roads, skies

    library = {
        "cars": [asdict(c) for c in cars.car_library()],
        "roads": [asdict(r) for r in roads.road_library()],
        "skies": [{**asdict(s), "light_group": s.light_group} for s in skies.sky_library()],
    }
    if as_json:
        print(json.dumps(library, indent=1))
        return
    for kind, rows in library.items():
        table = Table(title=f"{kind} ({len(rows)})")
        columns = list(rows[0])[:8]
        for col in columns:
            table.add_column(col)
        for row in rows:
            table.add_row(*(f"{row[c]:.3g}" if isinstance(row[c], float) else str(row[c]) for c in columns))
        console.print(table)


@app.callback(invoke_without_command=True)
def _version(version: Annotated[bool, typer.Option("--version", help="print the version")] = False) -> None:
    if version:
        print(__version__)
        raise typer.Exit()


def main() -> None:
    app(prog_name="metricscenes")


if __name__ == "__main__":
    sys.exit(main())
