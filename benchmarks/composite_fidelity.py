"""Composite fidelity: does plate + inset match a full-frame render of the scene?

    PYTHONPATH=. python benchmarks/composite_fidelity.py [--manifest manifests/quick.yaml]
        [--environment 0] [--distances 25 100 200] [--condition day] [--work DIR]

A collection holds each scene as a car-less *plate* (shared by an environment's six
scenes) with the car's *inset* pasted in (DESIGN §2). This script measures what that
costs. It renders, for one environment of a manifest at three distances, a small
collection restricted to the light groups of one condition, then renders each scene
*whole* (car and background in one render) twice with two other seeds, A and B:

1. at the reference grid over the whole frame (plate spp): the composite C (resampled
   to the reference grid) against A, inside the inset window, in a ring around it
   (out to one window size: where an uncaught shadow or reflection would show) and in
   the rest of the frame;
2. at the inset's own sampling over the inset window (inset spp): the stored inset
   against A (checks the window's registration: a one-pixel shift shows at edges).

In every region it reports the mean absolute difference over pixels and bands,
MAD(C - A), against MAD(B - A), the render noise of two full renders, both in % of the
region's mean radiance; the mean signed difference (bias), in %; and the same MADs
for luminance Y (what a camera integrates: far less noisy than one 10 nm band). C is
unbiased if bias(C - A) is as small as bias(B - A) and MAD(C - A) / MAD(B - A) is ≈ 1 where C has
the same noise as A (plate sampling) and ≈ 0.71 where C is much less noisy (the inset,
area-averaged from k² finer pixels: sqrt(σ_A²) / sqrt(2 σ_A²)).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from metricscenes import scene as scene_mod
from metricscenes.generate import generate, inset_window
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.groundtruth import car_box_tan
from metricscenes.manifest import load_manifest, parse_manifest
from metricscenes.photometry import radiance_to_xyz
from metricscenes.plan import plan_collection
from metricscenes.radiance import _overlap_matrix
from metricscenes.render import Film, render_radiance, use_variant
from metricscenes.store import Collection

REPO = Path(__file__).resolve().parents[1]
SEEDS = (0x5EED_A, 0x5EED_B)  # full renders A and B; the collection uses the manifest's seeds


def restricted_manifest(path: Path, environment: int, distances: list[float], condition: str):
    """The manifest cut down to environments 0..``environment``, three distances and one condition."""
    m = load_manifest(path)
    if condition not in m.conditions:
        raise SystemExit(f"error: unknown condition {condition!r} (manifest has: {', '.join(m.conditions)})")
    data = m.model_dump(mode="json")
    weights = {g: w for g, w in m.conditions[condition].items() if w > 0}
    data.update(name=f"{m.name}-fidelity", environments=environment + 1, distances_m=sorted(distances),
                light_groups=[g for g in m.light_groups if g in weights], conditions={condition: weights},
                illuminance_sweep=None)
    return parse_manifest(data, f"{path} (restricted)")


def render_whole(manifest, scene_plan, film: Film, spp: int, seed: int, weights: dict[str, float]) -> np.ndarray:
    """The scene, car included, rendered in one piece and mixed over the condition's light groups."""
    env = scene_plan.environment
    pose = scene_mod.car_pose(env, scene_plan.distance_m)
    parts = scene_mod.environment_parts(env, ground_to_horizon=bool(manifest.render.ground_to_horizon))
    parts = parts.merged(scene_mod.car_parts(env, pose))
    total = None
    for i, (group, w) in enumerate(sorted(weights.items())):
        if not scene_mod.has_emitters(parts, group):
            continue
        sd = scene_mod.scene_dict(env, parts, group, film, spp=spp, seed=seed + 7919 * i,
                                  max_depth=manifest.render.max_depth)
        cube = render_radiance(sd, spp) * np.float32(w)
        total = cube if total is None else total + cube
    return total


def coverage_on_grid(extent, cols: int, rows: int) -> np.ndarray:
    """(rows, cols) fraction of each reference-grid pixel covered by ``extent``."""
    e = REFERENCE_EXTENT
    cx = np.asarray(_overlap_matrix(extent.x0, extent.x1, 1, e.x0, e.x1, cols).sum(axis=1)).ravel()
    cy = np.asarray(_overlap_matrix(extent.y0, extent.y1, 1, e.y0, e.y1, rows).sum(axis=1)).ravel()
    return np.outer(cy, cx)


def region_stats(c: np.ndarray, a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> dict:
    """Spectral (all bands) and luminance (what a camera integrates) differences in a region."""
    ca, ba, ref = (c - a)[mask], (b - a)[mask], a[mask]
    mean = float(ref.mean())
    yc, ya, yb = (radiance_to_xyz(x)[..., 1][mask] for x in (c, a, b))
    y_mean = float(ya.mean())
    return {"pixels": int(mask.sum()), "mean_radiance": mean,
            "mad_ca_pct": 100 * float(np.abs(ca).mean()) / mean, "mad_ba_pct": 100 * float(np.abs(ba).mean()) / mean,
            "bias_ca_pct": 100 * float(ca.mean()) / mean, "bias_ba_pct": 100 * float(ba.mean()) / mean,
            "y_mad_ca_pct": 100 * float(np.abs(yc - ya).mean()) / y_mean,
            "y_mad_ba_pct": 100 * float(np.abs(yb - ya).mean()) / y_mean}


def measure(manifest, collection: Collection, scene_plan, condition: str) -> list[dict]:
    ref_w, ref_h = collection.reference_grid
    weights = collection.conditions[condition]
    spectral = collection.radiance(scene_plan.scene_id, condition)
    plate_spp, inset_spp = manifest.render.plate_spp, manifest.render.inset_spp
    rows = []
    # 1. whole frame at the reference grid
    comp = spectral.resample(ref_w, ref_h)
    a, b = (render_whole(manifest, scene_plan, Film(ref_w, ref_h), plate_spp, s, weights) for s in SEEDS)
    cover = coverage_on_grid(spectral.layers[1].extent, ref_w, ref_h)
    inside = cover > 0
    ys, xs = np.nonzero(inside)
    h, w = np.ptp(ys) + 1, np.ptp(xs) + 1
    ring = np.zeros_like(inside)
    ring[max(0, ys.min() - h):ys.max() + h + 1, max(0, xs.min() - w):xs.max() + w + 1] = True
    ring &= ~inside
    for region, mask in (("window", inside), ("ring", ring), ("rest", ~inside & ~ring)):
        rows.append({"grid": f"reference {ref_w}x{ref_h}", "region": region, **region_stats(comp, a, b, mask)})
    # 2. inset window at the inset's sampling
    pose = scene_mod.car_pose(scene_plan.environment, scene_plan.distance_m)
    box = car_box_tan(scene_mod.car_vertices(scene_plan.environment, pose))
    k, cx, cy, cw, ch = inset_window(box, manifest)
    film = Film(ref_w * k, ref_h * k, cx, cy, cw, ch)
    a, b = (render_whole(manifest, scene_plan, film, inset_spp, s, weights) for s in SEEDS)
    inset = spectral.layers[1].radiance
    rows.append({"grid": f"inset {cw}x{ch} (k={k})", "region": "window",
                 **region_stats(inset, a, b, np.ones(inset.shape[:2], dtype=bool))})
    return rows


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--manifest", type=Path, default=REPO / "manifests" / "quick.yaml")
    p.add_argument("--environment", type=int, default=0)
    p.add_argument("--distances", type=float, nargs="+", default=[25.0, 100.0, 200.0])
    p.add_argument("--condition", default="day")
    p.add_argument("--work", type=Path, default=Path("/tmp/composite-fidelity"))
    p.add_argument("--threads", type=int, default=None)
    args = p.parse_args(argv)
    manifest = restricted_manifest(args.manifest, args.environment, args.distances, args.condition)
    out = args.work / manifest.sha256()[:12]
    started = time.perf_counter()
    generate(manifest, out, threads=args.threads)  # resumes: a rerun only re-measures
    print(f"collection {out} ready in {time.perf_counter() - started:.1f} s")
    use_variant(manifest.render.variant, args.threads)
    collection = Collection.open(out)
    plans = [s for s in plan_collection(manifest) if s.environment.environment_id == args.environment]
    header = (f"{'scene':<14}{'grid':<24}{'region':<8}{'pixels':>7}{'mean L':>9}{'MAD C-A':>9}"
              f"{'MAD B-A':>9}{'ratio':>7}{'bias C-A':>9}{'bias B-A':>9}{'Y: MAD C-A':>11}{'MAD B-A':>9}{'ratio':>7}")
    print(f"condition {args.condition}; mean L in W sr-1 m-2 nm-1 over pixels and 31 bands; MAD and bias in % "
          f"of the region's mean (spectral: per band and pixel; Y: luminance per pixel)")
    print(header)
    print("-" * len(header))
    for s in plans:
        t = time.perf_counter()
        for r in measure(manifest, collection, s, args.condition):
            print(f"{s.scene_id:<14}{r['grid']:<24}{r['region']:<8}{r['pixels']:>7}{r['mean_radiance']:>9.4f}"
                  f"{r['mad_ca_pct']:>9.1f}{r['mad_ba_pct']:>9.1f}{r['mad_ca_pct'] / r['mad_ba_pct']:>7.2f}"
                  f"{r['bias_ca_pct']:>+9.2f}{r['bias_ba_pct']:>+9.2f}{r['y_mad_ca_pct']:>11.1f}"
                  f"{r['y_mad_ba_pct']:>9.1f}{r['y_mad_ca_pct'] / r['y_mad_ba_pct']:>7.2f}")
        print(f"{'':<14}({time.perf_counter() - t:.1f} s)")


if __name__ == "__main__":
    main()
