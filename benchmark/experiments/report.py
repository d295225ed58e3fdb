"""``benchmark report``: one self-contained HTML page from sweep and run folders.

One folder (a sweep or a single run) or several (:func:`load_many`: runs and sweeps of one
collection and one detector, e.g. ``benchmark report results/mine-day results/quick``) make
one page. It holds AP-vs-distance curves per condition (one line per camera), the System
Performance Maps and OD50 vs MTF50 (:mod:`benchmark.experiments.spm`; two or more MTF50
values only), a table (camera, MTF50 in cycles/mm on the sensor and cycles/mrad in object
space, focal length and field of view, condition, OD50 ± SD, AP range ± SD, AP per distance),
the miss rate and false positives per image at the working threshold per distance, and per
distance a strip of camera images, cropped around the car at the
same field of view for every camera, with the ground-truth box (green) and the best
car detection (red, with its score). Every image is embedded as base64 PNG and the
page loads nothing from elsewhere; the figures are also written as PNG and SVG next
to the page (``figures/``). Liu et al., EI 2023, Figs. 5-7; DESIGN §4.

``references``: a protocol whose reference submissions' AP per distance (the leaderboard's band,
:mod:`benchmark.leaderboard.band`) the runs are drawn over, "Beside the references", without
rendering them. Conditions are named by what they physically are
(:func:`benchmark.leaderboard.protocols.condition_label`) in titles, tables and headings.

Where the cameras differ in focal length the MTF50 axis of the figures is the angular one
(cycles/mrad in object space, :func:`benchmark.experiments.spm.mtf50_axis`); the captions say
which axis each figure uses.

**Minimum sample.** OD50 and AP range from fewer than :data:`benchmark.scoring.MIN_ENVIRONMENTS`
environments per distance are marked :data:`benchmark.scoring.FEW_MARK` (a footnote says why),
the page says "sample too small: ..." above the table instead of inviting a comparison, and
the OD50-vs-MTF50 figure fits no line through them (docs/scoring.md).
"""

from __future__ import annotations

import base64
import html
import io
import json
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from benchmark.experiments import spm  # noqa: E402
from benchmark.measure.mtf import camera_mtf50  # noqa: E402
from benchmark.result_files import TABLE_COLUMNS, CameraRecord, read_results, read_sweep_record  # noqa: E402
from benchmark.experiments.sweep import (  # noqa: E402
    illuminance_table,
    load_sweep,
    run_name,
    run_od50,
    with_censoring,
)
from benchmark.scoring import FEW_MARK, ap_range, few_footnote, mark_few, sample_too_small_text, too_few, working_point  # noqa: E402
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES  # noqa: E402
from benchmark.scoring.od50 import format_od50  # noqa: E402
from metricscenes.manifest import parse_illuminance_condition  # noqa: E402
from metricscenes.outputs import SWEEP_STAMP  # noqa: E402

GT_COLOUR, DET_COLOUR = (0, 200, 0), (230, 0, 0)
CAR_CATEGORY_ID = 3
THUMB_WIDTH_PX = 320


def load_results(results_dir) -> tuple[pd.DataFrame, pd.DataFrame, dict[tuple[str, str], Path], dict]:
    """(AP table, OD50 table, run folder per (camera, condition), metadata) of a sweep
    folder (``sweep.csv``) or of one ``benchmark run`` folder (``results.json``)."""
    root = Path(results_dir)
    if (root / "sweep.csv").is_file():
        table, od50 = load_sweep(root)
        meta, paths = {}, {}
        if (root / "sweep.json").is_file():
            record = read_sweep_record(root / "sweep.json")
            meta = record.model_dump(exclude_unset=True)  # the page's facts
            # sweep.json names each run's folder (tagged when an exposure policy overrode the cameras')
            paths = {(r.camera, r.condition): root / r.path for r in record.runs}
        runs = {(c, k): paths.get((c, k), root / "runs" / run_name(c, k))
                for c, k in od50[["camera", "condition"]].itertuples(index=False)}
        return table, od50, runs, meta
    if (root / SWEEP_STAMP).is_file():
        raise ValueError(f"{root} is a sweep that has not written its tables yet (no sweep.csv: still running, or "
                         "stopped): run the same `benchmark sweep` again to finish it")
    if not (root / "results.json").is_file():
        raise ValueError(f"{root} is neither a sweep folder (sweep.csv) nor a run folder (results.json)")
    results = read_results(root / "results.json")
    cam = results.camera
    mtf50, source = _run_mtf50(cam)
    ident = {"camera": cam.name, "pixel_um": cam.pixel_um, "f_number": cam.f_number,
             "mtf50_cy_per_mm": mtf50, "mtf50_source": source, "condition": results.condition}
    table = pd.DataFrame([{**ident, "distance_m": r.distance_m, "ap": r.ap, "ap50": r.ap50, "n_images": r.n_images}
                          for r in results.per_distance], columns=TABLE_COLUMNS)
    n_env = min((r.n_images for r in results.per_distance), default=0)  # one image per environment and distance
    try:
        boot = run_od50(root, n_resamples=BOOTSTRAP_RESAMPLES, seed=results.seed)
        od50_m, sd_m, (lo, hi), n_resamples = boot.od50_m, boot.sd_m, boot.ci95_m, boot.n_resamples
        ranges = (boot.ap_range_m, boot.ap_range_sd_m, *boot.ap_range_ci95_m)
    except ValueError:  # one environment: no bootstrap
        od50_m, sd_m, lo, hi, n_resamples = _num(results.od50_m), math.nan, math.nan, math.nan, None
        ranges = (ap_range(*results.ap_curve()), math.nan, math.nan, math.nan)
    od50 = pd.DataFrame([{**ident, "od50_m": od50_m, "sd_m": sd_m, "ci95_lo_m": lo, "ci95_hi_m": hi, "n_environments": n_env,
                          **dict(zip(("ap_range_m", "ap_range_sd_m", "ap_range_ci95_lo_m", "ap_range_ci95_hi_m"), ranges))}])
    od50 = with_censoring(od50, table)
    meta = {"collection": results.collection.model_dump(exclude_unset=True),
            "detector": results.detector.model_dump(exclude_unset=True) if results.detector else {},
            "seed": results.seed, "n_resamples": n_resamples}
    return table, od50, {(cam.name, results.condition): root}, meta


def load_many(results_dirs) -> tuple[pd.DataFrame, pd.DataFrame, dict[tuple[str, str], Path], dict]:
    """:func:`load_results` of several sweep and run folders as one: their tables side by side,
    refused in one line where they come from different collections or detectors (a page
    compares cameras, not scenes or detectors) or hold the same camera × condition twice."""
    folders = [Path(p) for p in results_dirs]
    if not folders:
        raise ValueError("no results folder given")
    loaded = [load_results(f) for f in folders]
    if len(loaded) == 1:
        return with_optics(*loaded[0])
    first_folder, (_, _, _, first) = folders[0], loaded[0]
    for folder, (_, _, _, meta) in zip(folders[1:], loaded[1:]):
        for what, key in (("collection", lambda m: m.get("collection", {}).get("manifest_sha256")),
                          ("detector", lambda m: (m.get("detector", {}).get("sha256"),
                                                  str(m.get("detector", {}).get("input_size"))))):
            if key(meta) != key(first):
                raise ValueError(f"{folder} and {first_folder} come from different {what}s: one report compares "
                                 "cameras on one collection with one detector")
    seen: dict[tuple[str, str], Path] = {}
    for folder, (_, _, runs, _) in zip(folders, loaded):
        for key in runs:
            if key in seen:
                raise ValueError(f"camera {key[0]} under {key[1]} is in both {seen[key]} and {folder}: keep one")
            seen[key] = folder
    table = pd.concat([t for t, _, _, _ in loaded], ignore_index=True)
    od50 = pd.concat([o for _, o, _, _ in loaded], ignore_index=True)
    runs = {k: v for _, _, r, _ in loaded for k, v in r.items()}
    meta = dict(first)
    for key in ("seed", "n_resamples", "mtf_source"):  # the page's facts: one value, or each folder's
        values = list(dict.fromkeys(str(m.get(key)) for _, _, _, m in loaded if m.get(key) is not None))
        meta[key] = values[0] if len(values) == 1 else (" / ".join(values) or None)
    return with_optics(table, od50, runs, meta)


def camera_optics(runs: dict[tuple[str, str], Path]) -> dict[str, dict]:
    """Per camera: focal length (mm) and field of view (degrees, h × v) from one of its runs'
    results.json (recorded there, else from the spec it holds); empty where no run says."""
    from benchmark.camera import CameraSpec, camera_from_dict

    out: dict[str, dict] = {}
    for (camera, _), folder in runs.items():
        if camera in out or not (Path(folder) / "results.json").is_file():
            continue
        try:
            record = read_results(Path(folder) / "results.json").camera
        except (OSError, ValueError):
            continue
        if record.focal_length_mm is not None and record.fov_deg:
            out[camera] = {"focal_length_mm": record.focal_length_mm, "fov_deg": list(record.fov_deg)}
            continue
        spec = {k: v for k, v in (record.spec or {}).items()}
        spec["sensor"] = {k: v for k, v in dict(spec.get("sensor") or {}).items()
                          if k not in CameraSpec.model_fields["sensor"].annotation.model_computed_fields}
        try:
            cam = camera_from_dict(spec)
        except ValueError:
            continue
        out[camera] = {"focal_length_mm": cam.optics.focal_length_mm, "fov_deg": [cam.hfov_deg, cam.vfov_deg]}
    return out


def with_optics(table: pd.DataFrame, od50: pd.DataFrame, runs: dict, meta: dict) -> tuple:
    """The tables with ``focal_length_mm`` and ``mtf50_cy_per_mrad`` filled in where a sweep
    written before they were recorded (or a single run) lacks them, from the runs'
    results.json, and ``fov_deg`` ("h × v") on the OD50 table; (table, od50, runs, meta)."""
    optics = camera_optics(runs)

    def fill(frame: pd.DataFrame) -> pd.DataFrame:
        frame = frame.copy()
        recorded = frame["focal_length_mm"] if "focal_length_mm" in frame.columns else pd.Series(np.nan, frame.index)
        read = frame["camera"].map(lambda c: optics.get(c, {}).get("focal_length_mm", np.nan))
        frame["focal_length_mm"] = recorded.astype(float).fillna(read.astype(float))
        frame["mtf50_cy_per_mrad"] = frame["mtf50_cy_per_mm"].astype(float) * frame["focal_length_mm"] / 1000.0
        return frame

    od50 = fill(od50)
    od50["fov_deg"] = od50["camera"].map(lambda c: "{:.1f} × {:.1f}".format(*optics[c]["fov_deg"]) if c in optics else "–")
    return fill(table), od50, runs, meta


def plot_ap_curves(table: pd.DataFrame, out=None, *, axis: str = "sensor"):
    """AP vs distance, one panel per condition, one line per camera (seaborn), cameras
    coloured by MTF50 on ``axis`` (:data:`benchmark.experiments.spm.MTF50_AXES`; paper Fig. 5)."""
    import seaborn as sns

    column, _, unit = spm.MTF50_AXES[axis]
    order = table.groupby("camera")[column].first().sort_values(kind="stable")
    digits = ".0f" if axis == "sensor" else ".2f"
    labels = {c: f"{c} ({m:{digits}} {unit})" if np.isfinite(m) else c for c, m in order.items()}
    data = table.assign(camera=table["camera"].map(labels))
    conditions = list(dict.fromkeys(table["condition"]))
    fig, axes = plt.subplots(1, len(conditions), figsize=(5.0 * len(conditions) + 1.6, 3.8), squeeze=False,
                             sharey=True, constrained_layout=True)
    palette = dict(zip(labels.values(), sns.color_palette("viridis", len(labels))))
    for ax, condition in zip(axes[0], conditions):
        sns.lineplot(data=data[data["condition"] == condition], x="distance_m", y="ap", hue="camera",
                     hue_order=list(labels.values()), palette=palette, marker="o", ax=ax, legend=ax is axes[0][-1])
        ax.axhline(0.5, color="grey", lw=0.8, ls=":")
        ax.set(title=_label(condition), xlabel="distance (m)", ylabel="AP (COCO @[.5:.95], car)", ylim=(-0.02, 1.02))
    legend = axes[0][-1].get_legend()
    if legend is not None:
        sns.move_legend(axes[0][-1], "upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, title="camera (MTF50)")
    if out is not None:
        spm.save_figure(fig, out)
    return fig


def summary_table(table: pd.DataFrame, od50: pd.DataFrame) -> pd.DataFrame:
    """One row per camera × condition: MTF50, OD50 ± SD, 95 % interval, AP range ± SD and its
    interval, AP per distance.

    A censored OD50 (``censored`` ">" or "<": AP does not cross 0.5 inside the measured
    distances) shows its bound, "> 200" or "< 25", with no ± and no interval: the number
    behind it is an extrapolation. OD50 and AP range from too few environments carry
    :data:`benchmark.scoring.FEW_MARK` (:func:`benchmark.scoring.mark_few`)."""
    ap = table.pivot_table(index=["camera", "condition"], columns="distance_m", values="ap", sort=False)
    ap.columns = [f"AP {d:g} m" for d in ap.columns]
    rows = od50.set_index(["camera", "condition"])
    n_env = _col(rows, "n_environments", None)
    out = pd.DataFrame({
        "MTF50 (cy/mm)": rows["mtf50_cy_per_mm"].map(lambda v: f"{v:.1f}" if np.isfinite(v) else "–"),
        "MTF50 (cy/mrad)": [_fmt(v, ".3f") for v in _col(rows, "mtf50_cy_per_mrad", np.nan)],
        "focal length (mm)": [_fmt(v, "g") for v in _col(rows, "focal_length_mm", np.nan)],
        "FOV (°)": _col(rows, "fov_deg", "–"),
        "OD50 ± SD (m)": [mark_few(_pm(o, s, c, b), n) for o, s, c, b, n in zip(
            rows["od50_m"], rows["sd_m"], _col(rows, "censored", ""), _col(rows, "bound_m", np.nan), n_env)],
        "95 % interval (m)": [_interval(lo, hi) if not c else "–" for lo, hi, c in zip(
            rows.get("ci95_lo_m", np.nan), rows.get("ci95_hi_m", np.nan), _col(rows, "censored", ""))],
        "AP range ± SD (m)": [mark_few(_pm(_num(v), _num(s)), n) for v, s, n in zip(
            _col(rows, "ap_range_m", np.nan), _col(rows, "ap_range_sd_m", np.nan), n_env)],
        "AP range 95 % (m)": [_interval(_num(lo), _num(hi)) for lo, hi in zip(
            _col(rows, "ap_range_ci95_lo_m", np.nan), _col(rows, "ap_range_ci95_hi_m", np.nan))],
    }, index=rows.index)
    out = out.join(ap.map(lambda v: f"{v:.3f}")).reset_index()
    return out.assign(condition=out["condition"].map(_label))


def working_point_table(runs: dict[tuple[str, str], Path]) -> pd.DataFrame | None:
    """Per camera × condition, per distance: "miss rate / false positives per image" at the working
    threshold, from each run's results.json (computed from its detections where an older run lacks
    them); None where no run has either."""
    rows = []
    for (camera, condition), folder in runs.items():
        per = _working_point(Path(folder))
        if per:
            rows.append({"camera": camera, "condition": _label(condition),
                         **{f"{d:g} m": f"{m:.2f} / {fp:.2f}" for d, (m, fp) in sorted(per.items())}})
    return pd.DataFrame(rows).fillna("–") if rows else None


def _working_point(folder: Path) -> dict[float, tuple[float, float]] | None:
    try:
        rows = read_results(folder / "results.json").per_distance
        if rows and all(r.miss_rate is not None and r.false_positives_per_image is not None for r in rows):
            return {r.distance_m: (r.miss_rate, r.false_positives_per_image) for r in rows}
        gt = json.loads((folder / "groundtruth.json").read_text())
        dets = json.loads((folder / "detections.json").read_text())
    except (OSError, ValueError):  # no run folder there (a sweep's table alone), or unreadable: not shown
        return None
    return {d: (r["miss_rate"], r["false_positives_per_image"]) for d, r in working_point(gt, dets).items()}


def crop_with_boxes(image_path: Path, gt_box, det, *, width_px: int = THUMB_WIDTH_PX):
    """A PIL thumbnail around the car: the crop spans 4 car widths (at least 12 % of the
    frame), the same fraction of the field of view for every camera; boxes drawn on the
    thumbnail so their lines stay crisp. ``gt_box``/``det['bbox']`` are COCO xywh pixels."""
    from PIL import Image, ImageDraw

    img = Image.open(image_path).convert("RGB")
    w, h = img.size
    bx, by, bw, bh = gt_box
    frac = float(np.clip(4.0 * bw / w, 0.12, 1.0))
    cw, ch = frac * w, frac * h
    x0 = float(np.clip(bx + bw / 2 - cw / 2, 0, w - cw))
    y0 = float(np.clip(by + bh / 2 - ch / 2, 0, h - ch))
    scale = width_px / cw
    thumb_h = max(1, round(ch * scale))
    resample = Image.Resampling.NEAREST if scale >= 1 else Image.Resampling.LANCZOS  # show the pixels
    thumb = img.resize((width_px, thumb_h), resample, box=(x0, y0, x0 + cw, y0 + ch))
    draw = ImageDraw.Draw(thumb)

    def rect(box):
        x, y, bw_, bh_ = box
        return [(x - x0) * scale, (y - y0) * scale, (x + bw_ - x0) * scale, (y + bh_ - y0) * scale]

    draw.rectangle(rect(gt_box), outline=GT_COLOUR, width=2)
    if det is not None:
        r = rect(det["bbox"])
        draw.rectangle(r, outline=DET_COLOUR, width=2)
        draw.text((max(0, r[0]), max(0, r[1] - 11)), f"car {det['score']:.2f}", fill=DET_COLOUR)
    return thumb


def image_strips(runs: dict[tuple[str, str], Path], table: pd.DataFrame) -> list[dict]:
    """Per distance and condition, one thumbnail per camera (first environment)."""
    strips: dict[tuple[float, str], list] = {}
    for (camera, condition), run_dir in runs.items():
        gt_path, det_path = run_dir / "groundtruth.json", run_dir / "detections.json"
        if not gt_path.is_file() or not (run_dir / "images").is_dir():
            continue
        gt = json.loads(gt_path.read_text())
        dets = json.loads(det_path.read_text()) if det_path.is_file() else []
        env = min(im["environment_id"] for im in gt["images"])
        boxes = {a["image_id"]: a["bbox"] for a in gt["annotations"] if a["category_id"] == CAR_CATEGORY_ID}
        best: dict[int, dict] = {}
        for d in dets:
            if d["category_id"] == CAR_CATEGORY_ID and d["score"] > best.get(d["image_id"], {"score": -1})["score"]:
                best[d["image_id"]] = d
        for im in gt["images"]:
            path = run_dir / "images" / f"{im['scene_id']}.png"
            if im["environment_id"] != env or im["id"] not in boxes or not path.is_file():
                continue
            ap = table.query("camera == @camera and condition == @condition and distance_m == @im['distance_m']")["ap"]
            strips.setdefault((float(im["distance_m"]), condition), []).append({
                "camera": camera, "scene_id": im["scene_id"], "ap": float(ap.iloc[0]) if len(ap) else float("nan"),
                "png": _png_base64(crop_with_boxes(path, boxes[im["id"]], best.get(im["id"]))),
                "score": best[im["id"]]["score"] if im["id"] in best else None,
            })
    order = {c: k for k, c in enumerate(dict.fromkeys(table["condition"]))}
    return [{"distance_m": d, "condition": c, "images": v} for (d, c), v in sorted(strips.items(), key=lambda kv: (kv[0][0], order.get(kv[0][1], 99)))]


def _label(condition: str) -> str:
    """What a condition physically is (:func:`benchmark.leaderboard.protocols.condition_label`)."""
    from benchmark.leaderboard.protocols import condition_label

    return condition_label(condition)


def plot_over_band(table: pd.DataFrame, band, protocol, out=None):
    """The runs' AP vs distance (a line per camera) over the references' band (lowest to highest
    AP shaded, median dashed), one panel per condition both hold; ``band``:
    :func:`benchmark.leaderboard.band.reference_band`. ValueError where they share no condition."""
    bands = [b for b in band if b.condition in set(table["condition"])]
    if not bands:
        raise ValueError(f"--references {protocol.name}: its references hold no condition of these runs "
                         f"(they hold {', '.join(b.condition for b in band)}; the runs {', '.join(dict.fromkeys(table['condition']))})")
    fig, axes = plt.subplots(1, len(bands), figsize=(4.6 * len(bands) + 1.6, 3.8), squeeze=False, sharey=True,
                             constrained_layout=True)
    cameras = list(dict.fromkeys(table["camera"]))
    for ax, b in zip(axes[0], bands):
        ax.fill_between(b.distances_m, b.lo, b.hi, color="#9ecae1", alpha=0.7, lw=0,
                        label=f"{b.n} references: lowest to highest")
        ax.plot(b.distances_m, b.median, "--", color="#08519c", lw=1.2, label="references: median")
        part = table[table["condition"] == b.condition]
        for k, camera in enumerate(cameras):
            rows = part[part["camera"] == camera].sort_values("distance_m")
            if not rows.empty:
                ax.plot(rows["distance_m"], rows["ap"], "o-", color=f"C{(k + 1) % 10}", lw=1.8, label=camera)
        ax.axhline(0.5, color="grey", lw=0.8, ls=":")
        ax.set(title=protocol.label(b.condition), xlabel="distance (m)", ylabel="AP (COCO @[.5:.95], car)",
               ylim=(-0.02, 1.02))
    axes[0][-1].legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7)
    if out is not None:
        spm.save_figure(fig, out)
    return fig


def _references_figure(table: pd.DataFrame, meta: dict, references: str, leaderboard_dir, fig_dir: Path) -> tuple:
    from benchmark.leaderboard.band import references_of

    manifest = meta.get("collection", {}).get("manifest_sha256")
    protocol, band = references_of(references, leaderboard_dir, manifest_sha256=manifest)
    n = max(b.n for b in band)
    caption = (f"AP vs distance of these runs over the {n} reference submissions of {protocol.name} "
               f"({protocol.references}, from {leaderboard_dir}) on the same collection: shaded from their lowest to "
               "their highest AP, dashed their median (from the AP per distance they submitted; nothing rendered "
               "again); dotted: AP 0.5.")
    return ("Beside the references", caption, plot_over_band(table, band, protocol, fig_dir / f"references_{protocol.name}"))


def report(results_dir, out=None, *, references: str | None = None, leaderboard_dir="leaderboard") -> Path:
    """Write ``report.html`` and its figures; returns the page's path. ``results_dir``: a
    sweep or run folder (the page goes there by default), or a list of them (:func:`load_many`;
    ``out`` required). ``references``: a protocol of the leaderboard in ``leaderboard_dir``
    whose references' band the runs are drawn over (:func:`plot_over_band`)."""
    folders = [Path(p) for p in results_dir] if isinstance(results_dir, (list, tuple)) else [Path(results_dir)]
    if out is None and len(folders) > 1:
        raise ValueError(f"{len(folders)} results folders: name the page with --out (e.g. --out report/report.html)")
    table, od50, runs, meta = load_many(folders)
    out = Path(out) if out is not None else folders[0] / "report.html"
    fig_dir = out.parent / "figures"
    is_lux = table["condition"].map(parse_illuminance_condition).notna()
    main, main_od50 = table[~is_lux], od50[~od50["condition"].map(parse_illuminance_condition).notna()]
    beside = [_references_figure(main, meta, references, leaderboard_dir, fig_dir)] if references else []
    figures = beside + (_main_figures(main, main_od50, fig_dir) if not main.empty else [])
    lux = illuminance_table(table)
    for camera, part in lux.groupby("camera", sort=False):
        if part["illuminance_lux"].nunique() >= 2 and part["distance_m"].nunique() >= 2:
            figures.append((f"SPM over illuminance · {camera}", "AP over (distance, scene illuminance) of the "
                            "collection's illuminance sweep, interpolated linearly in log illuminance.",
                            spm.spm_illuminance(part, fig_dir / f"spm_illuminance_{camera}")))
    sections = []
    for title, caption, fig in figures:
        sections.append(f"<h2>{html.escape(title)}</h2><figure><img alt='{html.escape(title)}' src='data:image/png;base64,"
                        f"{_fig_base64(fig)}'><figcaption>{html.escape(caption)}</figcaption></figure>")
        plt.close(fig)
    summary = summary_table(table, od50)
    few = [n for n in _col(od50, "n_environments", None) if too_few(n)]
    sections.append("<h2>Results</h2>"
                    + (f"<p class='verdict'>{html.escape(sample_too_small_text(min(few)))}: the figures marked "
                       f"{FEW_MARK} are shown, not compared, and no line is fitted through them.</p>" if few else "")
                    + summary.to_html(index=False, classes="results", border=0, escape=True)
                    + (f"<p class='note'>{html.escape(few_footnote())}. AP range: area under AP vs distance (m), defined "
                       "where OD50 is censored.</p>" if few else
                       "<p class='note'>AP range: area under AP vs distance (m), defined where OD50 is censored "
                       "(docs/scoring.md).</p>"))
    working = working_point_table(runs)
    if working is not None:
        sections.append("<h2>Miss rate and false positives</h2><p>At the working threshold, per distance: miss rate / "
                        "false positives per image (a car detection of score ≥ 0.25 overlapping the car at IoU ≥ 0.5 "
                        "finds it; the false positives are car detections at that score that do not; docs/scoring.md)."
                        "</p>" + working.to_html(index=False, classes="results", border=0, escape=True))
    strips = image_strips({k: v for k, v in runs.items() if parse_illuminance_condition(k[1]) is None}, table)
    if strips:
        sections.append("<h2>Images</h2><p>First environment, cropped around the car at the same field of view for "
                        "every camera; <span style='color:#0a0'>green</span>: ground truth, "
                        "<span style='color:#e00'>red</span>: best car detection and its score.</p>")
        for s in strips:
            cells = "".join(_thumb_html(i) for i in s["images"])
            sections.append(f"<h3>{s['distance_m']:g} m · {html.escape(_label(s['condition']))}</h3><div class='strip'>{cells}</div>")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(_page(meta, "\n".join(sections)), encoding="utf-8")
    summary.to_csv(out.parent / "report_table.csv", index=False)
    return out


def _main_figures(table: pd.DataFrame, od50: pd.DataFrame, fig_dir: Path) -> list[tuple]:
    """(title, caption, figure) of the curves, the MTF50 SPMs and OD50 vs MTF50 (where defined),
    on the MTF50 axis :func:`benchmark.experiments.spm.mtf50_axis` picks (named in each caption)."""
    axis = spm.mtf50_axis(table)
    column, _, unit = spm.MTF50_AXES[axis]
    why = spm.mtf50_axis_text(table, axis)
    figures = [("AP vs distance", f"COCO AP@[.5:.95] for the car at each distance; one line per camera, coloured by "
                f"MTF50 ({unit}); the dotted line is AP 0.5 (OD50). {why}.",
                plot_ap_curves(table, fig_dir / "ap_vs_distance", axis=axis))]
    per_condition = table.groupby("condition")[column].nunique()
    if table[column].notna().all() and (per_condition >= 2).all():
        mark = 100.0 if axis == "sensor" and table[column].min() <= 100 <= table[column].max() else None
        guide = "; dashed: OD50 at MTF50 100 cy/mm" if mark is not None else ""
        figures.append(("System Performance Maps", "AP over (distance, MTF50), linearly interpolated between the "
                        f"measured points (white); iso-AP lines every 0.1, the bold one is AP 0.5{guide}. {why}.",
                        spm.spm_mtf50(table, fig_dir / "spm_mtf50", mark_mtf50=mark, axis=axis)))
    if od50["camera"].nunique() >= 2 and od50[column].notna().all():
        measured = (float(table["distance_m"].min()), float(table["distance_m"].max()))
        figures.append(("OD50 vs MTF50", "OD50 with its 95 % bootstrap interval over environments; least-squares "
                        "line per condition through the OD50s inside the measured distances (none through OD50s from "
                        "too few environments: the legend says so), its slope in the "
                        "legend; hollow triangles: OD50 beyond the measured distances, drawn at the bound (▲ \u2018> farthest\u2019: a "
                        f"lower bound; ▼ \u2018< nearest\u2019), not fitted. {why}.",
                        spm.od50_vs_mtf50(od50, fig_dir / "od50_vs_mtf50", measured_range_m=measured, axis=axis)))
    return figures


def _thumb_html(item: dict) -> str:
    caption = f"{item['camera']} · AP {item['ap']:.2f}"
    score = item["score"]
    caption += " · no car detection" if score is None else f" · best car {score:.2f}" if score >= 0.01 else " · best car < 0.01"
    return (f"<figure class='thumb'><img alt='{html.escape(item['scene_id'])}' src='data:image/png;base64,{item['png']}'>"
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def _page(meta: dict, body: str) -> str:
    col, det = meta.get("collection", {}), meta.get("detector", {})
    facts = [("collection", f"{col.get('name', '?')} (manifest {str(col.get('manifest_sha256', ''))[:12]})"),
             ("detector", f"{det.get('name', '?')}, input size {det.get('input_size', '?')}"),
             ("seed", meta.get("seed")), ("bootstrap resamples", meta.get("n_resamples")),
             ("MTF50 source", meta.get("mtf_source"))]
    items = "".join(f"<li><b>{html.escape(k)}</b>: {html.escape(str(v))}</li>" for k, v in facts if v is not None)
    style = ("body{font-family:system-ui,sans-serif;margin:2em;max-width:1400px;color:#222}"
             "table.results{border-collapse:collapse;font-size:0.85em}"
             "table.results td,table.results th{padding:3px 8px;border-bottom:1px solid #ddd;text-align:right}"
             "figure{margin:0.5em 0}figure img{max-width:100%}.strip{display:flex;flex-wrap:wrap;gap:8px}"
             ".thumb{margin:0}.thumb figcaption{font-size:0.75em;text-align:center}")
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>metricscenes report</title>"
            f"<style>{style}</style></head><body><h1>metricscenes benchmark report</h1><ul>{items}</ul>\n{body}\n</body></html>\n")


def _run_mtf50(cam: CameraRecord) -> tuple[float, str]:
    """MTF50 of a run's camera as its results.json records it, else from the spec recorded
    there (NaN, "none": no spec, or no source gave one)."""
    from benchmark.camera import camera_from_dict

    if cam.mtf50_cy_per_mm is not None:
        return float(cam.mtf50_cy_per_mm), cam.mtf50_source or "measured"

    spec = json.loads(json.dumps(cam.spec or {}))
    spec.get("sensor", {}).pop("width_px", None), spec.get("sensor", {}).pop("height_px", None)  # computed fields
    try:
        value, source = camera_mtf50(camera_from_dict(spec))
    except ValueError:
        return float("nan"), "none"
    return (float("nan") if value is None else value), source


def _png_base64(image) -> str:
    buf = io.BytesIO()
    image.save(buf, format="PNG")
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _fig_base64(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _num(value) -> float:
    return float("nan") if value is None else float(value)


def _fmt(value, spec: str) -> str:
    return format(float(value), spec) if value is not None and np.isfinite(float(value)) else "–"


def _col(rows: pd.DataFrame, name: str, default) -> list:
    return list(rows[name]) if name in rows.columns else [default] * len(rows)


def _pm(value: float, sd: float, censored: str = "", bound_m: float = np.nan) -> str:
    if censored and np.isfinite(bound_m):
        return format_od50(value, censored, bound_m, unit="")
    if not np.isfinite(value):
        return "∞" if value == math.inf else "–"
    return f"{value:.1f} ± {sd:.1f}" if np.isfinite(sd) else f"{value:.1f}"


def _interval(lo: float, hi: float) -> str:
    if np.isnan(lo) or np.isnan(hi):
        return "–"
    return f"[{lo:.1f}, {hi:.1f}]".replace("inf", "∞")
