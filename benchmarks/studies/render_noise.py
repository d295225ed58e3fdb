"""Render noise at the reference camera: the Monte Carlo noise of metricscenes' radiance as
cam12 sees it, against cam12's own photon shot noise, in daylight, and the samples per
pixel (spp) that put it under a third of the shot noise.

    PYTHONPATH=. python benchmarks/studies/render_noise.py --manifest manifests/quick.yaml --units env000 env000-d050m \\
        [--collection collections/quick]
    PYTHONPATH=. python benchmarks/studies/render_noise.py --manifest manifests/quick.yaml --units env000 env000-d050m \\
        --spp 16 64
    PYTHONPATH=. python benchmarks/studies/render_noise.py --manifest manifests/quick.yaml --units env000 \\
        --plate-width 960 --plate-height 540 [--spp 16 64] [--window 8] [--dark-e 1] [--work DIR]

Method. Each unit (a plate ``envNNN``: the whole reference field; an inset
``envNNN-dDDDm``: the window around the car, over its environment's plate) is rendered
twice with metricscenes' own render path, differing only in seed
(``store_codecs.render_twice``: ``generate.render_unit`` with the unit's seed and with
another), with only the daylight light group rendered (``--light-group sky_day``: the
``day`` condition is ``{sky_day: 1}``). ``--spp`` sets the plates' and insets' spp,
``--plate-width``/``--plate-height`` the reference grid (the plates' grid; insets keep
``inset_pixel_mrad``). ``--collection``: render A, written as that collection's ``store``
writes it, must be the collection's array (checked by sha256 where the grid and render
settings are the collection's).

Each render becomes the scene a run hands the camera (a :class:`SpectralScene`: the
plate layer, and the inset layer over it at its extent) and goes through the camera's
pipeline (``benchmark.camera.pipeline.simulate``, what ``benchmark run`` calls) with
every sensor noise source off (``noise=False``: ``NoiseOptions.off()``). Render A is
captured with the camera's own exposure policy (cam12: ``auto_peak`` on the day scene);
render B with that same exposure time (a ``fixed`` policy), so the two captures differ
only in their radiance (the table's log line also says what B's own exposure would have
been). ``Capture.electrons`` is the noise-free signal of the Bayer mosaic, before
demosaicing: e = electron rate x exposure time.

Statistic. Per pixel, the difference of two independent renders has variance
2 sigma_r^2, so one render's noise is sigma_r^2 = (e_A - e_B)^2 / 2 (one sample: pooled
over pixels), and the camera's shot noise is sigma_s^2 = e = (e_A + e_B) / 2 (Poisson).
The ratio sigma_r / sigma_s is pooled as sqrt(sum (e_A - e_B)^2 / 2 / sum e) over the
used pixels of a region (the whole frame; for an inset, the sensor pixels inside its
window, ``INSET_MARGIN_PX`` in from its edges, where neither the plate nor the lens's blur
of the plate reaches), and over ``--window`` x ``--window`` pixel windows of the region
(median and 90th percentile over the windows with at least half their pixels used; R / G
/ B: the overall ratio per colour site of the mosaic). Left out: pixels that saturate in
either capture (e >= the sensor's saturation: well or ADC, 1146 e- for cam12) and dark
pixels, mean e below ``--dark-e`` (default: the read noise squared, 25 e- for cam12,
below which read noise, not shot noise, is the camera's noise). (Two renders with seeds
s, s+1 differ as much as s, s+100003: the seeds give independent renders.)

Reading it. The plate grid is coarser than cam12's pixels (quick's 480 x 270: one render
pixel spreads over 4 x 4 sensor pixels by interpolation), so render noise is correlated
over neighbouring sensor pixels while shot noise is not: the table says how many render
pixels a window holds (the window's independent samples). The high windows are on edges
(lane markings, the horizon, tree outlines: the pixel-footprint part of the estimate),
and a window's size decides how much flat area dilutes them, so the window percentiles
depend on ``--window`` (32 by default; with 8 the 90th percentile is lower on quick's
env000, the overall ratio is the same).

spp. If Monte Carlo noise fell as 1/sqrt(spp), the spp for ratio 1/3 would be
spp x (3 ratio)^2 (the "spp needed" column). metricscenes renders with Mitsuba's
``stratified`` sampler, and measured from 16 to 64 spp the ratio falls faster, about as
spp^-0.75: the 1/sqrt(spp) rule is then conservative when extrapolating up and wrong when
extrapolating down (from 64 spp it says 12 spp suffice where 16 spp measure 0.39). With
two or more ``--spp`` the script fits ratio ~ spp^-alpha and prints the spp where the
fitted line reaches 1/3 (interpolate between the measured spp; do not trust far beyond).
Renders are kept under ``--work`` (keyed by the manifest as rendered) and reused.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

# store_codecs: this script's sibling (the script's folder is first on sys.path).
from store_codecs import Renders, noise_manifest, render_twice

from benchmark.measure.render_noise import capture_pair, channel_ratios, fitted_spp, pooled_ratio, spp_needed, used_pixels

INSET_MARGIN_PX = 4  # sensor pixels left out along an inset window's edges (blend, lens blur)


def override_manifest(manifest, spp: int | None = None, width: int | None = None, height: int | None = None):
    """``manifest`` with its plate and inset spp set to ``spp`` and its reference grid (the
    plates' grid) set to ``width`` x ``height`` (None: as it is)."""
    from metricscenes.manifest import parse_manifest

    data = manifest.model_dump(mode="json")
    if spp is not None:
        data["render"] |= {"plate_spp": spp, "inset_spp": spp}
    if width is not None or height is not None:
        grid = data["reference_grid"]
        data["reference_grid"] = grid | {"width_px": width or grid["width_px"], "height_px": height or grid["height_px"]}
    return parse_manifest(data, "overridden manifest")


def inset_box(inset_extent, camera, field) -> tuple[slice, slice] | None:
    """Sensor rows and columns wholly inside an inset's extent, ``INSET_MARGIN_PX`` in from
    its edges, starting on a whole Bayer tile; None if nothing is left."""
    from benchmark.camera.pipeline import sensor_extent

    e = sensor_extent(camera, field)
    pitch_x, pitch_y = e.width / camera.width_px, e.height / camera.height_px

    def span(lo, hi, origin, pitch, n):
        first = int(np.ceil((lo - origin) / pitch - 1e-9)) + INSET_MARGIN_PX
        first += first % 2
        last = min(n, int(np.floor((hi - origin) / pitch + 1e-9)) - INSET_MARGIN_PX)
        return slice(max(first, 0), last) if last > first else None

    cols = span(inset_extent.x0, inset_extent.x1, e.x0, pitch_x, camera.width_px)
    rows = span(inset_extent.y0, inset_extent.y1, e.y0, pitch_y, camera.height_px)
    return None if cols is None or rows is None else (rows, cols)


def unit_renders(manifest, unit: str, work: Path) -> dict[str, dict[str, Renders]]:
    """The unit's renders by layer: ``plate`` (its environment's plate) and, for an inset
    unit, ``inset``; each a path -> :class:`Renders` of its light groups."""
    plate = unit.split("-")[0]
    layers = {"plate": render_twice(manifest, plate, work / plate)}
    if unit != plate:
        layers["inset"] = {p: r for p, r in render_twice(manifest, unit, work / unit).items()
                           if p.startswith("insets/")}
    return layers


def scenes(layers: dict[str, dict[str, Renders]], unit: str, inset_feather: float):
    """The two SpectralScenes (render A, render B) a camera is handed: each layer the sum
    of its light groups (weight 1: the day condition is ``{sky_day: 1}``), the inset
    feathered as the store's reader does (``Collection.radiance``)."""
    from metricscenes.radiance import RadianceLayer, SpectralScene

    out = []
    for which in ("a", "b"):
        stack = []
        for name, renders in layers.items():
            first = next(iter(renders.values()))
            total = sum(np.asarray(getattr(r, which), np.float32) for r in renders.values())
            stack.append(RadianceLayer(total, first.extent, feather=inset_feather if name == "inset" else 0.0))
        out.append(SpectralScene(layers=tuple(stack), metadata={"unit": unit, "render": which}))
    return out


def collection_check(collection, manifest, layers: dict[str, dict[str, Renders]]) -> str:
    """Whether render A of every array, written as the collection's ``store`` writes it
    (rounded, through the basis; ``manifest``, the one rendered here, has no store), is the
    collection's array (same sha256): yes / NO; n/a where there is nothing to compare (no
    collection, another grid or render settings, an array it has not got)."""
    from metricscenes.store import array_sha256
    from metricscenes.writer import read_back, stored_form

    if collection is None or (collection.manifest.render, collection.manifest.reference_grid) != (
            manifest.render, manifest.reference_grid):
        return "n/a"
    recorded = {p: collection.resolved.arrays.get(p) for renders in layers.values() for p in renders}
    if any(sha is None for sha in recorded.values()):
        return "n/a"
    store = collection.manifest.store
    mantissa_bits, basis_k = (None, None) if store is None else (store.mantissa_bits, store.spectral_basis)
    same = all(array_sha256(read_back(*stored_form(r.a, mantissa_bits, basis_k))) == recorded[p]
               for renders in layers.values() for p, r in renders.items())
    return "yes" if same else "NO"


def measure(manifest, units: list[str], camera, work: Path, window: int, dark_e: float | None,
            collection) -> list[dict]:
    """One row per unit and region (frame; inset window) of ``manifest`` as rendered here."""
    from benchmark.camera.sensor import saturation_electrons

    sensor = camera.sensor
    saturation = saturation_electrons(sensor)
    dark = sensor.read_noise_e**2 if dark_e is None else dark_e
    grid = manifest.reference_grid
    sensor_per_tan = camera.width_px / (2 * camera.tan_half_width)
    print(f"\n{manifest.name} as rendered here: {grid.width_px} x {grid.height_px} plates, "
          f"{manifest.render.plate_spp} spp plates, {manifest.render.inset_spp} spp insets, "
          f"light groups {', '.join(manifest.light_groups)}, variant {manifest.render.variant}; "
          f"camera {camera.name} ({camera.width_px} x {camera.height_px}, {camera.pixel_um} um, "
          f"exposure {camera.exposure.mode}); pixels used: below {saturation:.0f} e- (saturation) in both captures "
          f"and at least {dark:g} e- on average; {window} x {window} px windows", flush=True)
    rows = []
    for unit in units:
        layers = unit_renders(manifest, unit, work)
        started = time.perf_counter()
        scene_a, scene_b = scenes(layers, unit, manifest.render.inset_feather or 0.0)
        e_a, e_b, exposure_s, own_b = capture_pair(scene_a, scene_b, camera)
        used, left_out = used_pixels(e_a, e_b, saturation, dark)
        print(f"  {unit}: captured in {time.perf_counter() - started:.0f} s; exposure {1e3 * exposure_s:.3f} ms "
              f"(render B's own would be {1e3 * own_b:.3f} ms, {100 * (own_b / exposure_s - 1):+.2f} %); "
              f"left out: {100 * left_out['saturated']:.2f} % saturated, {100 * left_out['dark']:.2f} % dark", flush=True)
        regions = [("frame", (slice(None), slice(None)), manifest.render.plate_spp, "plate")]
        if "inset" in layers:
            box = inset_box(next(iter(layers["inset"].values())).extent, camera, grid.field)
            if box is None:
                print(f"  {unit}: its inset window covers no whole sensor pixel {INSET_MARGIN_PX} px in from its edges")
            else:
                regions.append(("inset window", box, manifest.render.inset_spp, "inset"))
        check = collection_check(collection, manifest, layers)
        for name, (rs, cs), spp, layer in regions:
            a, b, u = e_a[rs, cs], e_b[rs, cs], used[rs, cs]
            first = next(iter(layers[layer].values()))
            render_per_tan = first.a.shape[1] / first.extent.width  # the layer's pixels per tangent unit
            rows.append({"unit": unit, "region": name, "grid": f"{grid.width_px} x {grid.height_px}", "spp": spp,
                         "size": f"{a.shape[1]} x {a.shape[0]}", "check": check,
                         "stats": pooled_ratio(a, b, u, window), "channels": channel_ratios(a, b, u, sensor.cfa),
                         "per_window": (window * render_per_tan / sensor_per_tan) ** 2,
                         "median_e": float(np.median((a + b)[u] / 2)) if u.any() else float("nan")})
    return rows


def report(rows: list[dict]) -> None:
    print("\nrender noise / shot noise (noise-free captures of two renders; ratio < 1/3 wanted); "
          "spp needed: spp x (3 ratio)^2, i.e. noise ~ 1/sqrt(spp)\n")
    print("| unit | region | plate grid | sensor px | render A = collection | spp | px used | median e- "
          "| ratio overall | R / G / B | windows | render px per window | window median / p90 | windows > 1/3 "
          "| spp needed: overall / p90 |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        st = r["stats"]
        print(f"| {r['unit']} | {r['region']} | {r['grid']} | {r['size']} | {r['check']} | {r['spp']} "
              f"| {100 * st['used']:.1f} % | {r['median_e']:.0f} | {st['overall']:.3f} | {r['channels']} "
              f"| {st['windows']} | {r['per_window']:.1f} | {st['median']:.3f} / {st['p90']:.3f} "
              f"| {100 * st['above']:.1f} % | {spp_needed(r['spp'], st['overall']):.0f} / "
              f"{spp_needed(r['spp'], st['p90']):.0f} |")
    series: dict[tuple, list[dict]] = {}
    for r in rows:
        series.setdefault((r["unit"], r["region"], r["grid"]), []).append(r)
    fits = {key: rs for key, rs in series.items() if len({r["spp"] for r in rs}) > 1}
    if not fits:
        return
    print("\nmeasured convergence: ratio ~ spp^-alpha fitted over the spp rendered (1/sqrt(spp): alpha = 0.5), "
          "and the spp at which the fitted line reaches 1/3\n")
    print("| unit | region | plate grid | spp | alpha overall / median / p90 | spp for 1/3: overall / median / p90 |")
    print("|---|---|---|---|---|---|")
    for (unit, region, grid), rs in fits.items():
        fitted = [fitted_spp([(r["spp"], r["stats"][k]) for r in rs]) for k in ("overall", "median", "p90")]
        print(f"| {unit} | {region} | {grid} | {', '.join(str(r['spp']) for r in rs)} "
              f"| {' / '.join(f'{a:.2f}' for a, _ in fitted)} | {' / '.join(f'{n:.0f}' for _, n in fitted)} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", type=Path, required=True)
    parser.add_argument("--units", nargs="+", required=True, help="plates envNNN and insets envNNN-dDDDm")
    parser.add_argument("--camera", default="cam12", help="registry name or YAML (default: the reference, cam12)")
    parser.add_argument("--light-group", default="sky_day", help="the one light group rendered (daylight)")
    parser.add_argument("--spp", type=int, nargs="+",
                        help="plate and inset spp (default: the manifest's); two or more: the convergence is fitted")
    parser.add_argument("--plate-width", type=int, help="reference grid width, px (default: the manifest's)")
    parser.add_argument("--plate-height", type=int, help="reference grid height, px (16:9 with the width)")
    parser.add_argument("--window", type=int, default=32, help="pooling window, sensor px (default 32)")
    parser.add_argument("--dark-e", type=float, help="leave out pixels below this mean e- (default: read noise^2)")
    parser.add_argument("--collection", type=Path,
                        help="check render A against this collection's arrays (same manifest, grid and spp only)")
    parser.add_argument("--work", type=Path, default=Path("/tmp/render-noise"), help="renders kept here")
    args = parser.parse_args()
    from benchmark.camera import load_camera
    from metricscenes.manifest import load_manifest
    from metricscenes.store import Collection

    load = os.getloadavg()
    print(f"{os.cpu_count()} CPUs, load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}", flush=True)
    base = load_manifest(args.manifest)
    collection = Collection.open(args.collection) if args.collection else None
    camera = load_camera(args.camera)
    rows = []
    for spp in args.spp or [None]:
        manifest = noise_manifest(override_manifest(base, spp, args.plate_width, args.plate_height), [args.light_group])
        rows += measure(manifest, args.units, camera, args.work / manifest.sha256()[:12], args.window, args.dark_e,
                        collection)
    report(rows)


if __name__ == "__main__":
    main()
