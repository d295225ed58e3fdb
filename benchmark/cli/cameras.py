"""``benchmark cameras``: list, show and measure (MTF50) the registry's cameras.

``list`` shows the paper's 13 and, after them, the packaged extra cameras (``auto-*``),
marked ``extra``: loaded by name, never part of ``--cameras all``.

Mounted by the main CLI as ``app.add_typer(cameras_app, name="cameras")``. Errors print
one line and exit with code 2. Every MTF50 shown comes in cycles/mm on the sensor and in
cycles/mrad in object space (× focal length / 1000: what compares cameras whose focal
lengths differ), beside the focal length and the field of view.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.table import Table

from benchmark.camera import CameraSpec, extra_camera_names, list_cameras, load_camera
from benchmark.cli.help import HELP_SETTINGS
from metricscenes.cli_support import fail

app = typer.Typer(help="The camera registry: list, show, measure MTF50.", no_args_is_help=True,
                  rich_markup_mode=None, context_settings=HELP_SETTINGS)
_out = Console()


def _load(names: list[str]) -> list[CameraSpec]:
    try:
        return [load_camera(n) for n in names] if names else list_cameras()
    except ValueError as exc:
        fail(str(exc))


def _summary(cam: CameraSpec, *, extra: bool = False) -> dict:
    return {
        "name": cam.name,
        "extra": extra,
        "label": cam.label,
        "pixel_um": cam.pixel_um,
        "f_number": cam.f_number,
        "width_px": cam.width_px,
        "height_px": cam.height_px,
        "mtf50_group": cam.mtf50_group_cy_per_mm,
        "mtf50_group_cy_per_mrad": _round(cam.cy_per_mrad(cam.mtf50_group_cy_per_mm), 4),
        "focal_length_mm": cam.optics.focal_length_mm,
        "fov_deg": [round(cam.hfov_deg, 2), round(cam.vfov_deg, 2)],
        "sha256": cam.sha256(),
    }


@app.command("list")
def list_command(as_json: bool = typer.Option(False, "--json", help="Print JSON.")) -> None:
    """List the registry's cameras: the paper's 13, then the extra cameras (marked extra:
    loaded by name, not in --cameras all)."""
    paper = [_summary(c) for c in _load([])]
    extras = [_summary(c, extra=True) for c in _load(extra_camera_names())]
    if as_json:
        print(json.dumps(paper + extras, indent=2))
        return
    table = Table(title="Cameras (MTF50 group: the paper's, cycles/mm on the sensor and cycles/mrad in object space)",
                  caption="extra: packaged beside the paper's 13, loaded by name, not in --cameras all")
    # the name whole however narrow the terminal: it is what `run --camera` takes
    table.add_column("name", no_wrap=True, min_width=max(len(r["name"]) for r in paper + extras))
    table.add_column("set", no_wrap=True, min_width=len("extra"))
    for col in ("pixel µm", "f-number", "size px", "focal mm", "FOV °", "MTF50 group cy/mm", "cy/mrad", "sha256"):
        table.add_column(col)
    for r in paper:
        table.add_row(*_list_cells(r))
    table.add_section()  # a rule between the 13 and the extras
    for r in extras:
        table.add_row(*_list_cells(r))
    _out.print(table)


def _list_cells(r: dict) -> list[str]:
    """A ``cameras list`` table row from a :func:`_summary`."""
    return [r["name"], "extra" if r["extra"] else "paper", f"{r['pixel_um']:.1f}", f"{r['f_number']:.1f}",
            f"{r['width_px']}x{r['height_px']}", f"{r['focal_length_mm']:g}", "{:.1f} x {:.1f}".format(*r["fov_deg"]),
            f"{r['mtf50_group'] or '-'}", _cell(r["mtf50_group_cy_per_mrad"], ".3f"), r["sha256"][:12]]


@app.command("show")
def show_command(
    name: str = typer.Argument(..., help="cam01..cam13, an extra camera (auto-imx490-like), a number, or a YAML path."),
    as_json: bool = typer.Option(False, "--json", help="Print JSON."),
) -> None:
    """Show a camera's resolved spec (defaults filled in) and what it implies: field of
    view, IFOV, Nyquist, MTF50 through the whole chain, saturation, dynamic range, SNR at
    100 lux, and the datasheet figures measured on its photon transfer (dynamic range,
    SNR10 and SNR1 illuminance, HDR transitions); warnings."""
    from benchmark.measure.figures import camera_figures, camera_warnings, figure_rows

    cam = _load([name])[0]
    try:
        figures = camera_figures(cam)
        warnings = camera_warnings(cam, figures)
    except ValueError as exc:  # e.g. a QE file that cannot be read
        fail(f"{cam.name}: {str(exc).splitlines()[0]}")
    data = {**cam.model_dump(mode="json"), "sha256": cam.sha256()}
    if as_json:
        print(json.dumps({**data, "derived": figures, "warnings": warnings}, indent=2))
        return
    table = Table(title=f"{cam.name}: {cam.label}")
    table.add_column("field")
    table.add_column("value")
    for section, values in data.items():
        if isinstance(values, dict):
            for key, value in values.items():
                table.add_row(f"{section}.{key}", str(value))
        else:
            table.add_row(section, str(values))
    _out.print(table)
    implied = Table(title="What the spec implies")
    implied.add_column("figure")
    implied.add_column("value")
    for label, value in figure_rows(figures):
        implied.add_row(label, value)
    _out.print(implied)
    for line in warnings:
        _out.print(f"[bold yellow]warning:[/] {line}", highlight=False)


@app.command("mtf")
def mtf_command(
    names: Optional[list[str]] = typer.Argument(None, help="Cameras (default: all 13; extra cameras by name)."),
    as_json: bool = typer.Option(False, "--json", help="Print JSON."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write the MTF curves to this image."),
    isp_name: Optional[str] = typer.Option(
        None, "--isp", help="ISP preset for every camera instead of its own: default (the project's) or "
        "iset-parity (ISETCam's default image processor: bilinear, no white balance)."),
    esfr: str = typer.Option(
        "iso", "--esfr", help="e-SFR: iso (ISO 12233:2017, 5° edge) or isetcam (ISETCam's ISO12233v1 "
        "and MTF50 rule on its 21° edge)."),
) -> None:
    """Measure MTF50 (ISO 12233 e-SFR through optics + sensor + demosaic)."""
    from benchmark.camera.spec_isp import isp_preset
    from benchmark.measure.mtf import measure_mtf50, mtf50_analytic_cy_per_mm, mtf_readings

    cams = _load(names or [])
    if esfr not in ("iso", "isetcam"):
        fail(f"unknown e-SFR {esfr!r} (allowed: iso, isetcam)")
    if isp_name is not None:
        try:
            preset = isp_preset(isp_name)
        except ValueError as exc:
            fail(str(exc))
        cams = [cam.model_copy(update={"isp": preset}) for cam in cams]
    # the plain command's output stays as it was; the options are named where they apply
    tagged = isp_name is not None or esfr != "iso"
    results, curves = [], []
    for cam in cams:
        try:
            m = measure_mtf50(cam, esfr=esfr)
        except ValueError as exc:
            fail(f"{cam.name}: {exc}")
        curves.append({"name": cam.name, "pixel_um": cam.pixel_um, "freq_cy_per_mm": m["freq_cy_per_mm"], "mtf": m["mtf"]})
        read = mtf_readings(m["freq_cy_per_mm"], m["mtf"], cam.pixel_um)  # MTF30, MTF10 off the same curve
        results.append({
            "name": cam.name,
            "pixel_um": cam.pixel_um,
            "f_number": cam.f_number,
            "focal_length_mm": cam.optics.focal_length_mm,
            "fov_deg": [round(cam.hfov_deg, 2), round(cam.vfov_deg, 2)],
            "mtf50_cy_per_mm": round(m["mtf50_cy_per_mm"], 2),
            "mtf50_cy_per_mrad": _round(cam.cy_per_mrad(m["mtf50_cy_per_mm"]), 4),
            "mtf50_analytic_cy_per_mm": round(mtf50_analytic_cy_per_mm(
                cam.pixel_um, cam.f_number, sensor_spec=cam.sensor, optics=cam.optics), 2),
            "mtf50_group": cam.mtf50_group_cy_per_mm,
            "nyquist_cy_per_mm": round(500.0 / cam.pixel_um, 2),
            "mtf50_cy_per_px": _round(m["mtf50_cy_per_px"], 4),
            "mtf30_cy_per_mm": _round(read["mtf30_cy_per_mm"], 2),
            "mtf30_cy_per_px": _round(read["mtf30_cy_per_px"], 4),
            "mtf10_cy_per_mm": _round(read["mtf10_cy_per_mm"], 2),
            "mtf10_cy_per_px": _round(read["mtf10_cy_per_px"], 4),
            **({"isp": isp_name or "camera", "esfr": esfr} if tagged else {}),
            **({"chain": chain} if (chain := _chain(cam)) else {}),
        })
    if plot is not None:
        _plot(curves, plot)
    if as_json:
        print(json.dumps(results, indent=2))
        return
    title = ("MTF50 (cycles/mm on the sensor; cy/mrad: in object space, x focal length / 1000); "
             "analytic = diffraction x pixel, polychromatic")
    if tagged:
        title += f"; ISP {isp_name or 'of each camera'}, e-SFR {esfr}"
    table = Table(title=title)
    for col in ("name", "pixel µm", "f-number", "focal mm", "FOV °", "measured", "cy/mrad", "analytic", "paper group",
                "Nyquist", "MTF30", "MTF10"):
        table.add_column(col, justify="right")
    for r in results:
        table.add_row(r["name"], f"{r['pixel_um']:.1f}", f"{r['f_number']:.1f}", f"{r['focal_length_mm']:g}",
                      "{:.1f} x {:.1f}".format(*r["fov_deg"]), f"{r['mtf50_cy_per_mm']:.1f}",
                      _cell(r["mtf50_cy_per_mrad"], ".3f"), f"{r['mtf50_analytic_cy_per_mm']:.1f}",
                      f"{r['mtf50_group'] or '-'}", f"{r['nyquist_cy_per_mm']:.0f}",
                      _cell(r["mtf30_cy_per_mm"], ".1f"), _cell(r["mtf10_cy_per_mm"], ".1f"))
    _out.print(table)
    _out.print("measured = MTF50; MTF30, MTF10 read off the same curve ('-': not reached below 1 cycle/pixel); "
               "cy/mrad compares cameras of different focal lengths, cy/mm does not", highlight=False)
    for r in results:
        per_px = ", ".join(f"MTF{n} {_cell(r[f'mtf{n}_cy_per_px'], '.3f')}" for n in (50, 30, 10))
        _out.print(f"{r['name']} in cycles/pixel (Nyquist 0.5): {per_px}", highlight=False)
    for r in results:
        if "chain" in r:
            _out.print(f"{r['name']}: MTF50 through the whole chain: {r['chain']}", highlight=False)


def _chain(cam: CameraSpec) -> str | None:
    """What the edge goes through beyond a Bayer sensor read once (an HDR pixel's merge and
    companding, a clear-pixel tile's demosaic and luminance), or None for such a sensor."""
    from benchmark.camera.dual_gain import readouts

    dcg, parts = cam.sensor.dcg, []
    if dcg is not None:
        parts.append(f"{' + '.join(r.name for r in readouts(cam.sensor))} readouts merged to {dcg.merged_bits} bits, "
                     f"companded to {dcg.companded_bits} and decompanded")
    if cam.sensor.cfa != "RGGB":
        parts.append(f"{cam.sensor.cfa} demosaic ({cam.isp.demosaic}), luminance = the clear channel")
    return "; ".join(parts) or None


def _round(value: float | None, digits: int) -> float | None:
    """Rounded, or None (JSON null) for None or NaN: a level the curve does not reach."""
    return None if value is None or value != value else round(float(value), digits)


def _cell(value: float | None, fmt: str) -> str:
    return "-" if value is None else format(value, fmt)


def _plot(curves: list[dict], path: Path) -> None:
    """The curves with Nyquist, MTF50/30/10 and a cycles/pixel axis (:func:`benchmark.measure.mtf.mtf_figure`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from benchmark.measure.mtf import mtf_figure

    fig = mtf_figure(curves)
    try:
        fig.savefig(path, dpi=120, bbox_inches="tight")
    except (OSError, ValueError) as exc:
        fail(f"cannot write plot {path}: {exc}")
    finally:
        plt.close(fig)
