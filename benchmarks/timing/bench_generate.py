"""Rendering cost of one environment: plates + insets against full frames at inset sampling.

Renders, for one environment of a manifest, its plate and the inset of each distance
(one light group), timing each, and measures the renderer's sample rate on a full
frame at the inset's sampling over a strip, to extrapolate what a full frame at that
sampling would cost. Prints times and the ratio (a baseline measured in the same run,
since these machines are noisy).

    python benchmarks/timing/bench_generate.py [manifests/quick.yaml] [--group sky_day]
"""

from __future__ import annotations

import argparse
import os
import time

from metricscenes import scene as scene_mod
from metricscenes.generate import scene_inset_window
from metricscenes.manifest import load_manifest
from metricscenes.plan import plan_collection
from metricscenes.render import Film, render_radiance, use_variant


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manifest", nargs="?", default="manifests/quick.yaml")
    parser.add_argument("--group", default="sky_day")
    args = parser.parse_args()
    m = load_manifest(args.manifest)
    use_variant(m.render.variant)
    scenes = [s for s in plan_collection(m) if s.environment.environment_id == 0]
    env = scenes[0].environment
    ref_w, ref_h = m.reference_grid.width_px, m.reference_grid.height_px
    parts = scene_mod.environment_parts(env)

    def timed(parts_, film, spp):
        sd = scene_mod.scene_dict(env, parts_, args.group, film, spp=spp, seed=1, max_depth=m.render.max_depth)
        t = time.perf_counter()
        render_radiance(sd, spp)
        return time.perf_counter() - t

    plate_s = timed(parts, Film(ref_w, ref_h), m.render.plate_spp)
    inset_s, inset_px, biggest_k = 0.0, 0, 1
    for s in scenes:
        pose = scene_mod.car_pose(env, s.distance_m)
        with_car = parts.merged(scene_mod.car_parts(env, pose))
        k, cx, cy, cw, ch = scene_inset_window(m, env, scene_mod.car_vertices(env, pose))
        biggest_k = max(biggest_k, k)
        inset_s += timed(with_car, Film(ref_w * k, ref_h * k, cx, cy, cw, ch), m.render.inset_spp)
        inset_px += cw * ch
    # Baseline: a full frame at the finest inset sampling, timed on a strip and scaled up.
    strip_h = 32
    fine_w, fine_h = ref_w * biggest_k, ref_h * biggest_k
    strip_s = timed(parts, Film(fine_w, fine_h, 0, fine_h // 2, fine_w, strip_h), m.render.inset_spp)
    full_frame_s = strip_s * fine_h / strip_h * len(scenes)
    rate = (ref_w * ref_h * m.render.plate_spp + inset_px * m.render.inset_spp) / (plate_s + inset_s)
    print(f"manifest {m.name}: environment 0, light group {args.group}, {os.cpu_count()} CPUs, "
          f"load {os.getloadavg()[0]:.1f}")
    print(f"plate {ref_w}x{ref_h} @ {m.render.plate_spp} spp: {plate_s:.2f} s")
    print(f"{len(scenes)} insets ({inset_px} px in all) @ {m.render.inset_spp} spp: {inset_s:.2f} s")
    print(f"sample rate: {rate / 1e6:.2f} M spectral samples/s")
    print(f"baseline, {len(scenes)} full frames {fine_w}x{fine_h} at the inset sampling (extrapolated): "
          f"{full_frame_s:.0f} s")
    print(f"ratio baseline / (plate + insets): {full_frame_s / (plate_s + inset_s):.0f}x")


if __name__ == "__main__":
    main()
