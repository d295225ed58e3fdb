"""What a camera collects from the car at night: exposure time, electrons on the car body,
and what sets the exposure (the central region's brightest pixels): docs/data/night-exposure.csv
and night-exposure-regulation.csv (``benchmark publish night-exposure``).

For every scene the camera simulation runs without temporal noise; per scene it writes
the car's heading, the exposure time (ms), the median signal electrons of the green pixels inside the car's
ground-truth box, the same in the central region (the exposure policy's window), the
central region's 99.9th percentile and its ratio to the region's median, and which
fraction of the region is within a factor 2 of that peak (lamps, glare). A histogram of
log10 electrons in the central region is drawn for a few scenes (``--histograms``).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from benchmark.camera.pipeline import simulate
from benchmark.camera import load_camera
from benchmark.camera.exposure import central_region, parse_exposure, with_exposure
from metricscenes.store import Collection, scale_groundtruth


def green_sites(electrons: np.ndarray, rows: slice, cols: slice) -> np.ndarray:
    """Green pixels (RGGB: (0, 1) and (1, 0) sites) of a window of a mosaic."""
    win = np.zeros(electrons.shape, bool)
    win[rows, cols] = True
    green = np.zeros(electrons.shape, bool)
    green[0::2, 1::2] = True
    green[1::2, 0::2] = True
    return electrons[win & green]


def central_histograms(collection: Collection, camera, condition: str, scene_ids: list[str], path: Path) -> None:
    """Histograms of log10 signal electrons in the central region, one line per scene, with
    the reference policy's peak (the 99.9th percentile) marked."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3.6))
    bins = np.linspace(-3, 3.5, 131)
    for sid in scene_ids:
        e = simulate(collection.radiance(sid, condition), camera, seed=0, noise=False).electrons
        region = e[central_region(e.shape, camera.exposure.region_fraction)]
        line, = ax.plot(bins[:-1], np.histogram(np.log10(np.maximum(region, 1e-3)), bins)[0] / region.size,
                        drawstyle="steps-post", label=sid)
        ax.axvline(np.log10(np.percentile(region, 99.9)), color=line.get_color(), ls=":", lw=1)
    ax.set_yscale("log")
    ax.set_xlabel("log10 signal electrons (noise-free) in the central region")
    ax.set_ylabel("fraction of pixels")
    ax.set_title(f"{camera.name}, {condition}, {camera.exposure.mode}: dotted = 99.9th percentile")
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def scene_rows(collection: Collection, camera, condition: str) -> list[dict]:
    gt = scale_groundtruth(collection.groundtruth(), camera.width_px, camera.height_px)
    boxes = {a["image_id"]: a["bbox"] for a in gt["annotations"]}
    heading = {im["id"]: im["heading"] for im in gt["images"]}
    out = []
    for scene in collection.scenes():
        capture = simulate(collection.radiance(scene.scene_id, condition), camera, seed=0, noise=False)
        e = capture.electrons
        x, y, w, h = boxes[scene.image_id]
        car = green_sites(e, slice(int(y), int(np.ceil(y + h))), slice(int(x), int(np.ceil(x + w))))
        region = e[central_region(e.shape, camera.exposure.region_fraction)]
        peak = float(np.percentile(region, 99.9))
        out.append({
            "camera": camera.name, "condition": condition, "exposure_mode": camera.exposure.mode,
            "scene_id": scene.scene_id, "heading": heading[scene.image_id], "distance_m": scene.distance_m,
            "exposure_ms": round(1e3 * capture.exposure_s, 4),
            "car_median_e": round(float(np.median(car)), 2),
            "region_median_e": round(float(np.median(region)), 3),
            "region_p999_e": round(peak, 1),
            "peak_over_median": round(peak / max(float(np.median(region)), 1e-9), 1),
            "fraction_near_peak": float(f"{np.mean(region >= 0.5 * peak):.2e}"),
        })
    return out


def night_exposure(collection: Collection, cameras: list[str], condition: str, exposure: str | None = None,
                   say=print) -> list[dict]:
    """:func:`scene_rows` of every camera (``exposure``: an acquisition policy replacing each
    camera's own, as ``benchmark run --exposure``); ``say`` gets each camera's medians per
    heading and distance."""
    rows = []
    for name in cameras:
        camera = load_camera(name)
        if exposure:
            camera = with_exposure(camera, parse_exposure(exposure))
        rows += scene_rows(collection, camera, condition)
        groups: dict[tuple, list[dict]] = {}
        for r in rows:
            if r["camera"] == name:
                groups.setdefault((r["heading"], r["distance_m"]), []).append(r)
        for (head, d), rs in sorted(groups.items()):
            say(f"{name} {condition} {head:8s} {d:5.0f} m: exposure {np.median([r['exposure_ms'] for r in rs]):7.3f} ms, "
                f"car {np.median([r['car_median_e'] for r in rs]):8.2f} e-, "
                f"peak/median {np.median([r['peak_over_median'] for r in rs]):8.1f}")
    return rows


def write_rows(rows: list[dict], out: Path) -> None:
    """``rows`` as a CSV, columns in the first row's order."""
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
