"""The car lamps' whole frame on a coarser grid (``render.frame_divisor``): what it saves
and what the reference camera sees of it, at night.

    PYTHONPATH=. python benchmarks/studies/frame_sampling.py --collection /tmp/m300-2 \\
        --units env001-d050m env001-d150m --divisors 2 4 [--camera cam12] [--condition night]

Every inset unit also renders ``frames/<scene>/car_lights``: the car's lamps over the whole
view at the plates' sampling (an oncoming car's beams light the road far outside its
inset). In metric-300 that is as many samples as one plate light group, six times per
environment. This script renders, for a scene of a collection made without a divisor,
that frame again with another seed (A', the render noise) and on grids ``d`` times
coarser (B_d, its own seed), with metricscenes' render path
(:func:`metricscenes.lightgroups.render_pass`, the unit's scene with the car), timing each.

The camera is handed the scene under the condition (the collection's plate, frame and
inset, as ``Collection.radiance`` gives it: A) and the same with the frame replaced by A'
or by B_d interpolated onto the plate's grid, as the reader does for a collection made
with ``frame_divisor`` (``radiance.on_grid_of``). All are captured with every sensor noise
off, at A's exposure. Per pair, as in ``render_noise.py``: sqrt(sum (e_1 - e_2)^2 / 2 /
sum e) over the pixels lit (at least ``--dark-e`` e- on average, below saturation), the
whole frame and 32 x 32 windows (median, 90th percentile). A against A' is the render
noise of a frame at full sampling; A against B_d adds B_d's own noise and the loss of
detail. Where the two agree, a coarser frame loses nothing the camera can tell from the
render's own noise, which the spp were chosen to keep under a third of the shot noise.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from benchmark.measure.render_noise import capture_pair, pooled_ratio, used_pixels


def frame_renders(collection, unit_key: str, divisors: list[int], work: Path) -> dict:
    """The scene's car-lamp frame rendered again: ``"A'"`` (full grid, another seed) and
    ``d`` (grid / d) -> (radiance, seconds); kept in ``work`` and reused."""
    from metricscenes import scene as scene_mod
    from metricscenes.generate import plan_units
    from metricscenes.lightgroups import render_pass
    from metricscenes.plan import plan_collection
    from metricscenes.render import Film, use_variant

    manifest = collection.manifest
    use_variant(collection.render_variant)
    unit = next((u for u in plan_units(plan_collection(manifest)) if u.key == unit_key), None)
    if unit is None or unit.kind == "plate":
        raise SystemExit(f"{unit_key}: not an inset unit of {manifest.name}")
    env = unit.environment
    parts = scene_mod.environment_parts(env, ground_to_horizon=bool(manifest.render.ground_to_horizon))
    parts = parts.merged(scene_mod.car_parts(env, scene_mod.car_pose(env, unit.distance_m)))
    grid = manifest.reference_grid
    out = {}
    work = work / collection.manifest_sha256[:12] / unit_key
    work.mkdir(parents=True, exist_ok=True)
    for name, d in (("A'", 1), *((d, d) for d in divisors)):
        kept = work / f"frame-{d}.npz"
        if kept.is_file():
            with np.load(kept) as saved:
                out[name] = (saved["radiance"], float(saved["seconds"]))
            continue
        film = Film(grid.width_px // d, grid.height_px // d, field=grid.field)
        started = time.perf_counter()
        image = render_pass(env, parts, ("car_lights",), film, spp=manifest.render.plate_spp,
                            seed=unit.seed + 104729 + d, max_depth=manifest.render.max_depth)["car_lights"]
        out[name] = (np.asarray(image, np.float32), time.perf_counter() - started)
        np.savez(kept, radiance=out[name][0], seconds=out[name][1])
        print(f"  {unit_key}: frame {film.width} x {film.height} rendered in {out[name][1]:.1f} s", flush=True)
    return out


def with_frame(scene, frame_a: np.ndarray, frame: np.ndarray, weight: float):
    """``scene`` (plate + frame A, inset) with its frame A replaced by ``frame``, put on the
    plate's grid as the store's reader does."""
    from dataclasses import replace

    from metricscenes.radiance import RadianceLayer, on_grid_of

    plate = scene.layers[0]
    other = on_grid_of(RadianceLayer(frame, plate.extent), plate)
    radiance = plate.radiance - np.float32(weight) * frame_a + np.float32(weight) * other
    return replace(scene, layers=(RadianceLayer(radiance, plate.extent), *scene.layers[1:]))


def main() -> None:
    from benchmark.camera import load_camera
    from benchmark.camera.exposure import parse_exposure, with_exposure
    from benchmark.camera.sensor import saturation_electrons
    from metricscenes.store import Collection

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", type=Path, required=True, help="made without render.frame_divisor")
    parser.add_argument("--units", nargs="+", required=True, help="inset units envNNN-dDDDm")
    parser.add_argument("--divisors", type=int, nargs="+", default=[2, 4])
    parser.add_argument("--camera", default="cam12")
    parser.add_argument("--condition", default="night")
    parser.add_argument("--exposure", help="the camera's exposure policy instead of its own (as benchmark sweep's)")
    parser.add_argument("--window", type=int, default=32)
    parser.add_argument("--work", type=Path, default=Path("/tmp/frame-sampling"), help="renders kept here")
    parser.add_argument("--dark-e", type=float, help="leave out pixels below this mean e- (default: read noise^2)")
    args = parser.parse_args()

    collection = Collection.open(args.collection)
    if collection.manifest.render.frame_divisor:
        raise SystemExit(f"{args.collection}: its frames are already coarser (frame_divisor "
                         f"{collection.manifest.render.frame_divisor})")
    camera = load_camera(args.camera)
    if args.exposure:
        camera = with_exposure(camera, parse_exposure(args.exposure))
    saturation = saturation_electrons(camera.sensor)
    dark = camera.sensor.read_noise_e ** 2 if args.dark_e is None else args.dark_e
    if args.condition not in collection.conditions:
        raise SystemExit(f"{args.condition}: not a condition of {collection.name} ({', '.join(collection.conditions)})")
    weight = collection.conditions[args.condition].get("car_lights", 0.0)
    if weight == 0.0:
        raise SystemExit(f"{args.condition}: the car's lamps are off under this condition")
    grid = collection.manifest.reference_grid
    print(f"{collection.name}: {grid.width_px} x {grid.height_px} plates, {collection.manifest.render.plate_spp} spp, "
          f"variant {collection.render_variant}; camera {camera.name} (exposure {camera.exposure.mode}), "
          f"condition {args.condition}", flush=True)
    rows = []
    for unit in args.units:
        renders = frame_renders(collection, unit, args.divisors, args.work)
        scene = collection.radiance(unit, args.condition)
        # The car's lamps alone: the plate layer is then the frame (plates have no car_lights).
        frame_a = collection.radiance(unit, {"car_lights": 1.0}).layers[0].radiance
        seconds_a = renders["A'"][1]
        for name, (frame, seconds) in renders.items():
            e_a, e_x, exposure_s, _ = capture_pair(scene, with_frame(scene, frame_a, frame, weight), camera)
            used, _ = used_pixels(e_a, e_x, saturation, dark)
            stats = pooled_ratio(e_a, e_x, used, args.window)
            rows.append((unit, "A' (full grid, another seed)" if name == "A'" else f"B_{name} (grid / {name})",
                         f"{frame.shape[1]} x {frame.shape[0]}", seconds, seconds / seconds_a, stats,
                         float(np.median((e_a + e_x)[used] / 2)) if used.any() else float("nan"), exposure_s))
    print(f"\nA = the collection's scene under {args.condition}; the other frame in its place; noise-free "
          f"{camera.name} captures at A's exposure; lit: at least {dark:g} e- and below {saturation:.0f} e-\n")
    print("| scene | exposure ms | frame against A's | frame grid | render s | time vs full | lit px | median e- | "
          "ratio overall | windows median / p90 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for unit, name, size, seconds, rel, st, median_e, exposure_s in rows:
        print(f"| {unit} | {1e3 * exposure_s:.3f} | {name} | {size} | {seconds:.1f} | {rel:.3f} | {100 * st['used']:.1f} % "
              f"| {median_e:.0f} | "
              f"{st['overall']:.3f} | {st['median']:.3f} / {st['p90']:.3f} |")


if __name__ == "__main__":
    main()
