"""Composite fidelity: does plate + inset match a full-frame render of the scene?

    PYTHONPATH=. python benchmarks/studies/composite_fidelity.py [--manifest manifests/quick.yaml]
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

    PYTHONPATH=. python benchmarks/studies/composite_fidelity.py --seam [--collection DIR]
        [--manifest manifests/quick.yaml] [--distances 100 200] [--cameras cam12 8mm]

``--seam`` measures instead whether the inset's window shows in a camera's image (no full
renders: it needs only the collection, ``--collection`` or the restricted one rendered as
above). Each scene is captured noise-free (sensor noise off, D65 white balance: what is left
is the composite and the render's own noise) by each camera, with the inset composited both
ways (``Collection.radiance(..., inset_resolution=...)``): ``window`` (the inset's own
resolution over its whole window, the composite before) and ``car`` (its own resolution on
the car only), and the car-less plate alone at the same exposure. The CIELAB difference
ΔE*ab per pixel between the two images (sRGB as the detector sees it) is zero outside the
window; away from the car it is what the window shows: reported in bands of
``SEAM_BAND_PX`` pixels along each edge of the window inside the frame, just inward of its
feather ramp (mean, and the worst row or column along an edge: where the horizon crosses),
over the whole window (mean, 99th percentile) and outside it; and the detail ratio in the
window, mean |∇L*| of the composite over the plate's (1: as sharp as the plate around it).
``8mm`` is cam12's sensor behind an 8 mm lens with 2.1 µm pixels
(1920 × 1080, 28.3° × 16.1°: 0.26 mrad a pixel, finer than cam12's 0.32), a narrower camera
than the paper's; any registry name or YAML path works.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from benchmark.measure.seam import SEAM_BAND_PX, seam_check
from metricscenes import scene as scene_mod
from metricscenes.generate import generate, scene_inset_window
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.manifest import load_manifest, parse_manifest
from metricscenes.photometry import radiance_to_xyz
from metricscenes.plan import plan_collection
from metricscenes.radiance import _overlap_matrix
from metricscenes.render import Film, render_radiance, use_variant
from metricscenes.store import Collection

REPO = Path(__file__).resolve().parents[2]
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
    k, cx, cy, cw, ch = scene_inset_window(manifest, scene_plan.environment,
                                           scene_mod.car_vertices(scene_plan.environment, pose))
    film = Film(ref_w * k, ref_h * k, cx, cy, cw, ch)
    a, b = (render_whole(manifest, scene_plan, film, inset_spp, s, weights) for s in SEEDS)
    inset = spectral.layers[1].radiance
    rows.append({"grid": f"inset {cw}x{ch} (k={k})", "region": "window",
                 **region_stats(inset, a, b, np.ones(inset.shape[:2], dtype=bool))})
    return rows


def seam_camera(name: str):
    """A camera by registry name or YAML path; ``8mm``: cam12's sensor behind an 8 mm lens with
    2.1 µm pixels, 1920 × 1080 (a narrower camera, finer in angle than cam12)."""
    import yaml

    from benchmark.camera import load_camera
    from benchmark.camera.registry import DATA_DIR, camera_from_dict

    if name != "8mm":
        return load_camera(name)
    data = yaml.safe_load((DATA_DIR / "cam12.yaml").read_text())
    data.update(name="cam12-8mm-2.1um", label="cam12's sensor, 2.1 um pixel, 8 mm lens at f/1.9",
                mtf50_group_cy_per_mm=None)
    data["optics"]["focal_length_mm"] = 8.0
    data["sensor"].update(pixel_um=2.1, active_width_mm=4.032, active_height_mm=2.268)
    return camera_from_dict(data, source="8mm")


def seam_main(args, collection: Collection) -> None:
    scenes = [s.scene_id for s in collection.scenes()
              if s.environment_id == args.environment and any(abs(s.distance_m - d) < 1e-6 for d in args.distances)]
    if not scenes:
        raise SystemExit(f"error: no scene of environment {args.environment} at {args.distances} m "
                         f"in {collection.root}")
    print(f"condition {args.condition}; noise-free captures (D65 white balance); ΔE*ab per pixel of the composite's "
          f"image against the car-less plate's (same exposure), away from the car: in {SEAM_BAND_PX}-px bands along "
          f"the window's edges inward of its ramp (mean; worst line), over the window (mean; 99th pct), outside it; "
          f"detail: mean |grad L*| in the window, composite / plate")
    header = (f"{'camera':<18}{'scene':<14}{'inset':<8}{'border':>8}{'worst line':>11}{'window':>8}{'p99':>7}"
              f"{'outside':>8}{'detail':>8}")
    print(header)
    print("-" * len(header))
    for name in args.cameras:
        camera = seam_camera(name)
        for scene_id in scenes:
            for mode in ("window", "car"):
                r = seam_check(collection, scene_id, args.condition, camera, mode)
                print(f"{camera.name:<18}{scene_id:<14}{mode:<8}{r['border_de']:>8.2f}{r['border_de_max_line']:>11.1f}"
                      f"{r['window_de']:>8.2f}{r['window_de_p99']:>7.1f}{r['outside_de']:>8.2f}"
                      f"{r['detail_ratio']:>8.2f}")


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--manifest", type=Path, default=REPO / "manifests" / "quick.yaml")
    p.add_argument("--environment", type=int, default=0)
    p.add_argument("--distances", type=float, nargs="+", default=[25.0, 100.0, 200.0])
    p.add_argument("--condition", default="day")
    p.add_argument("--work", type=Path, default=Path("/tmp/composite-fidelity"))
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--seam", action="store_true", help="measure the window's seam in camera images instead")
    p.add_argument("--collection", type=Path, default=None,
                   help="with --seam: an existing collection (e.g. collections/quick) instead of rendering one")
    p.add_argument("--cameras", nargs="+", default=["cam12", "8mm"], help="with --seam (8mm: see the docstring)")
    args = p.parse_args(argv)
    if args.seam and args.collection is not None:
        seam_main(args, Collection.open(args.collection))
        return
    manifest = restricted_manifest(args.manifest, args.environment, args.distances, args.condition)
    out = args.work / manifest.sha256()[:12]
    started = time.perf_counter()
    generate(manifest, out, threads=args.threads)  # resumes: a rerun only re-measures
    print(f"collection {out} ready in {time.perf_counter() - started:.1f} s")
    if args.seam:
        seam_main(args, Collection.open(out))
        return
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
