"""One pass for all light groups against one render per group, on one inset.

Renders the inset of environment 0 at one distance with every light group of a manifest,
once per group (Mitsuba's ``path``, as scalar variants do) and in the passes of
:func:`metricscenes.lightgroups.passes` (the first sky with every lamp group, other
skies alone), each twice with different seeds: the first render of a kind pays the
kernel compilation (JIT variants), the second shows the render itself. Prints both and
their ratios (a baseline in the same run: these machines are noisy); then the one pass at
50 and 100 m, whose windows differ: with the window's numbers opaque, a new window costs a
render, not a compilation.

    python benchmarks/timing/bench_light_groups.py [manifests/quick.yaml] [--variant llvm_ad_spectral]
        [--distance 25]
"""

from __future__ import annotations

import argparse
import os
import time

from metricscenes import scene as scene_mod
from metricscenes.generate import scene_inset_window
from metricscenes.lightgroups import passes, render_pass
from metricscenes.manifest import load_manifest
from metricscenes.plan import plan_collection
from metricscenes.render import Film, render_radiance, use_variant


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("manifest", nargs="?", default="manifests/quick.yaml")
    parser.add_argument("--variant", default="llvm_ad_spectral")
    parser.add_argument("--distance", type=float, default=25.0)
    args = parser.parse_args()
    m = load_manifest(args.manifest)
    use_variant(args.variant)
    env = next(s for s in plan_collection(m) if s.environment.environment_id == 0).environment
    grid = m.reference_grid

    def inset(distance: float):
        """The scene parts with the car at ``distance`` and its inset's film."""
        pose = scene_mod.car_pose(env, distance)
        k, cx, cy, cw, ch = scene_inset_window(m, env, scene_mod.car_vertices(env, pose))
        return (scene_mod.environment_parts(env).merged(scene_mod.car_parts(env, pose)),
                Film(grid.width_px * k, grid.height_px * k, cx, cy, cw, ch, field=grid.field))

    parts, film = inset(args.distance)
    cw, ch = film.size
    spp, depth = m.render.inset_spp, m.render.max_depth
    groups = [g for g in m.light_groups if scene_mod.has_emitters(parts, g)]

    def per_group(seed: int) -> float:
        t = time.perf_counter()
        for i, group in enumerate(groups):
            render_radiance(scene_mod.scene_dict(env, parts, group, film, spp=spp, seed=seed + i, max_depth=depth), spp)
        return time.perf_counter() - t

    def one_pass(seed: int) -> float:
        t = time.perf_counter()
        for i, pass_groups in enumerate(passes(groups)):
            render_pass(env, parts, pass_groups, film, spp=spp, seed=seed + i, max_depth=depth)
        return time.perf_counter() - t

    print(f"manifest {m.name}, environment 0, inset at {args.distance:g} m ({cw} x {ch} px, {spp} spp), "
          f"{args.variant}, {len(groups)} groups in {len(passes(groups))} passes; {os.cpu_count()} CPUs, "
          f"load {os.getloadavg()[0]:.1f}")
    times = {"per group": [per_group(1), per_group(101)]}
    if args.variant.startswith("scalar"):  # (the one pass traces Python: JIT variants only)
        print(f"per group : {times['per group'][0]:.1f} s, again {times['per group'][1]:.1f} s")
        return
    times["one pass"] = [one_pass(1), one_pass(101)]
    for name, (first, second) in times.items():
        print(f"{name:10s}: first {first:7.1f} s (with compilation), second {second:6.1f} s")
    (f1, s1), (f2, s2) = times["per group"], times["one pass"]
    print(f"ratio per group / one pass: first {f1 / f2:.2f}x, second {s1 / s2:.2f}x")
    # A new window (another distance, another inset scale) keeps the one pass's kernels.
    for distance in (50.0, 100.0):
        other_parts, other_film = inset(distance)
        t = time.perf_counter()
        for i, pass_groups in enumerate(passes(groups)):
            render_pass(env, other_parts, pass_groups, other_film, spp=spp, seed=201 + i, max_depth=depth)
        w2, h2 = other_film.size
        print(f"one pass at {distance:g} m (first render of a new window, {w2} x {h2} px, "
              f"scale {other_film.width // grid.width_px}): "
              f"{time.perf_counter() - t:.1f} s")
    samples = cw * ch * spp * len(groups)
    print(f"samples per group and pixel, all groups: {samples / 1e6:.1f} M; "
          f"one pass {samples / s2 / 1e6:.2f} M group-samples/s, per group {samples / s1 / 1e6:.2f} M/s")


if __name__ == "__main__":
    main()
