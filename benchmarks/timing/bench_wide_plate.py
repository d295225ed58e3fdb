"""What a wide plate costs against the reference plate it surrounds, measured in one run (these
machines are shared: the ratio is the figure): one light group of one environment of a manifest
with a ``wide_plate``, each rendered on one thread with the manifest's samples per pixel.

    PYTHONPATH=. python benchmarks/timing/bench_wide_plate.py manifests/adas-quick.yaml [--group sky_day] [--environment 0]
"""

from __future__ import annotations

import argparse
import os
import time

from metricscenes import scene as scene_mod
from metricscenes.manifest import load_manifest
from metricscenes.plan import plan_environment
from metricscenes.render import Film, render_radiance, use_variant


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manifest")
    parser.add_argument("--group", default="sky_day")
    parser.add_argument("--environment", type=int, default=0)
    args = parser.parse_args()
    m = load_manifest(args.manifest)
    if m.wide_plate is None:
        raise SystemExit(f"{args.manifest}: has no wide_plate")
    use_variant("scalar_spectral", 1)
    env = plan_environment(m, args.environment)
    parts = scene_mod.environment_parts(env, ground_to_horizon=bool(m.render.ground_to_horizon),
                                        road_end_m=m.render.road_end_m)
    grid, wide = m.reference_grid, m.wide_plate
    rates = {}
    for name, (w, h, field, spp) in {"reference plate": (grid.width_px, grid.height_px, grid.field, m.render.plate_spp),
                                     "wide plate": (wide.width_px, wide.height_px, wide.field, wide.spp)}.items():
        scene = scene_mod.scene_dict(env, parts, args.group, Film(w, h, field=field), spp=spp, seed=1,
                                     max_depth=m.render.max_depth)
        start = time.perf_counter()
        render_radiance(scene, spp)
        seconds = time.perf_counter() - start
        rates[name] = (seconds, w * h * spp)
        print(f"{name}: {w} x {h} at {spp} spp, {seconds:.1f} s on one thread, "
              f"{w * h * spp / seconds / 1e6:.2f} M samples/s")
    (t_ref, n_ref), (t_wide, n_wide) = rates.values()
    print(f"wide / reference: {t_wide / t_ref:.2f} x the time for {n_wide / n_ref:.2f} x the samples "
          f"(load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
