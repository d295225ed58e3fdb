"""System Performance Maps (SPMs) and OD50 vs MTF50 (Liu et al., EI 2023, Figs. 6-8).

An SPM shows AP as a function of one system or scene factor and object distance: the
measured points (camera MTF50 × distance, or illuminance × distance) are interpolated
on a regular grid (``scipy.interpolate.griddata``, linear on the Delaunay triangulation
of the points, axes rescaled to the unit square so neither unit dominates), drawn as
filled contours with labelled iso-AP lines, and the measured points on top. The
AP = 0.5 line is the OD50 contour.

Every plotting function returns the :class:`matplotlib.figure.Figure` and, given
``out``, writes ``out.png`` and ``out.svg`` (the Agg backend: no display needed).

**Which MTF50.** MTF50 in cycles/mm on the sensor ranks cameras by sharpness only when they
share a focal length (the paper's 13 do: 4.38 mm). Across focal lengths the comparable
figure is the angular one, cycles/mrad in object space (MTF50 × focal length / 1000): an
8 mm camera with 168.6 cy/mm resolves 1.35 cy/mrad, finer than cam12's 229.3 cy/mm
(1.00 cy/mrad). :func:`mtf50_axis` picks the angular axis where the compared cameras'
focal lengths differ and the sensor-plane one otherwise, and every figure names its axis.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; never a window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from scipy.interpolate import griddata  # noqa: E402

MTF50_AXES = {
    "sensor": ("mtf50_cy_per_mm", "MTF50 (cycles/mm on the sensor)", "cy/mm"),
    "angular": ("mtf50_cy_per_mrad", "MTF50 (cycles/mrad in object space)", "cy/mrad"),
}
"""(table column, axis label, unit) of each MTF50 axis."""
AP_LEVELS = np.linspace(0.0, 1.0, 11)
ISO_AP_LEVELS = np.round(np.linspace(0.1, 0.9, 9), 2)
CONDITION_COLOURS = {"day": "tab:orange", "dusk": "tab:purple", "night": "tab:blue"}


def focal_lengths_mm(table: pd.DataFrame) -> dict[str, float]:
    """The focal length of each camera in a sweep or OD50 table (NaN where not recorded)."""
    if "focal_length_mm" not in table.columns:
        return {c: float("nan") for c in dict.fromkeys(table["camera"])}
    return {c: float(v) for c, v in table.groupby("camera", sort=False)["focal_length_mm"].first().items()}


def mtf50_axis(table: pd.DataFrame) -> str:
    """``"angular"`` (cycles/mrad in object space) where the cameras of ``table`` differ in
    focal length and every one has its angular MTF50, else ``"sensor"`` (cycles/mm: the
    paper's axis, which orders cameras of one focal length as the angular one would)."""
    focal = np.array(list(focal_lengths_mm(table).values()), dtype=float)
    if focal.size < 2 or not np.isfinite(focal).all() or np.ptp(focal) <= 1e-9 * focal.max():
        return "sensor"
    column = MTF50_AXES["angular"][0]
    if column not in table.columns or not np.isfinite(table[column].astype(float)).all():
        return "sensor"
    return "angular"


def mtf50_axis_text(table: pd.DataFrame, axis: str) -> str:
    """Why the figures use ``axis``, for a caption: "MTF50 in cycles/mrad in object space
    (MTF50 × focal length / 1000): the focal lengths differ (4.38, 8 mm)"."""
    focal = sorted({round(v, 3) for v in focal_lengths_mm(table).values() if np.isfinite(v)})
    lengths = ", ".join(f"{v:g}" for v in focal)
    if axis == "angular":
        return (f"MTF50 in cycles/mrad in object space (MTF50 × focal length / 1000): the cameras' focal lengths "
                f"differ ({lengths} mm), and on the sensor (cycles/mm) a longer lens would look less sharp than it is")
    if len(focal) == 1:
        return f"MTF50 in cycles/mm on the sensor: every camera has the same {lengths} mm focal length"
    return "MTF50 in cycles/mm on the sensor"


def _label(condition: str) -> str:
    """What a condition physically is (:func:`benchmark.leaderboard.protocols.condition_label`)."""
    from benchmark.leaderboard.protocols import condition_label

    return condition_label(condition)


def save_figure(fig, out) -> list[Path]:
    """Write ``out.png`` (150 dpi) and ``out.svg``; returns the two paths."""
    out = Path(out)
    out = out.with_suffix("") if out.suffix.lower() in (".png", ".svg") else out
    out.parent.mkdir(parents=True, exist_ok=True)
    paths = [out.with_name(out.name + ".png"), out.with_name(out.name + ".svg")]
    with plt.rc_context({"svg.hashsalt": "metricscenes", "svg.fonttype": "path"}):  # deterministic, font-free SVG
        fig.savefig(paths[0], dpi=150, bbox_inches="tight")
        fig.savefig(paths[1], bbox_inches="tight", metadata={"Date": None})
    return paths


def interpolate_map(x, y, z, *, n: int = 101, log_x: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linear interpolation of scattered ``z(x, y)`` on a grid (the SPM surface).

    Repeated (x, y) points are averaged first. The grid axes are ``n`` even steps over
    the data's range (in log10 for ``log_x``) merged with every measured coordinate,
    so each measured point is a grid node and the surface passes through it exactly.
    Outside the points' convex hull the surface is NaN (no extrapolation).

    Returns:
        (gx of shape (nx,), gy of shape (ny,), gz of shape (ny, nx)).
    """
    frame = pd.DataFrame({"x": np.asarray(x, float), "y": np.asarray(y, float), "z": np.asarray(z, float)})
    frame = frame[np.isfinite(frame).all(axis=1)]
    if log_x:
        if (frame["x"] <= 0).any():
            raise ValueError("log_x needs positive x values (illuminance_lux > 0)")
        frame["x"] = np.log10(frame["x"])
    frame = frame.groupby(["x", "y"], as_index=False)["z"].mean()
    if frame["x"].nunique() < 2 or frame["y"].nunique() < 2:
        raise ValueError(f"an SPM needs two or more distinct values on each axis, got {frame['x'].nunique()} x "
                         f"{frame['y'].nunique()} from {len(frame)} finite points")
    gx = np.union1d(np.linspace(frame["x"].min(), frame["x"].max(), n), frame["x"].unique())
    gy = np.union1d(np.linspace(frame["y"].min(), frame["y"].max(), n), frame["y"].unique())
    mx, my = np.meshgrid(gx, gy)
    gz = griddata(frame[["x", "y"]].to_numpy(), frame["z"].to_numpy(), (mx, my), method="linear", rescale=True)
    return (10.0**gx if log_x else gx), gy, gz


def _draw_map(ax, gx, gy, gz, px, py, *, cmap: str = "viridis"):
    gz = np.clip(gz, 0.0, 1.0)  # round-off below AP 0 would leave the AP-0 region unfilled (NaN stays NaN)
    filled = ax.contourf(gx, gy, gz, levels=AP_LEVELS, cmap=cmap, vmin=0.0, vmax=1.0, extend="neither")
    lines = ax.contour(gx, gy, gz, levels=ISO_AP_LEVELS, colors="k", linewidths=0.7)
    widths = [1.8 if abs(level - 0.5) < 1e-9 else 0.7 for level in lines.levels]  # the OD50 contour
    lines.set_linewidths(widths)
    ax.clabel(lines, fmt="%.1f", fontsize=7, inline=True)
    ax.scatter(px, py, s=14, c="white", edgecolors="k", linewidths=0.6, zorder=3, label="measured", clip_on=False)
    return filled


def _mark_od50(ax, gx, gy, gz, y_value: float) -> float | None:
    """Dashed guide to the distance where AP = 0.5 at ``y_value`` (paper Fig. 6, left)."""
    from benchmark.scoring import od50

    if not gy.min() <= y_value <= gy.max():
        return None
    row = np.array([np.interp(y_value, gy, gz[:, j]) for j in range(gx.size)])
    ok = np.isfinite(row)
    if ok.sum() < 2:
        return None
    d = od50(gx[ok], row[ok])
    if not np.isfinite(d) or not gx.min() <= d <= gx.max():
        return None
    ax.plot([gx.min(), d, d], [y_value, y_value, gy.min()], "--", color="crimson", lw=1.2,
            label=f"OD50 = {d:.0f} m at {y_value:g}")
    return float(d)


def spm_mtf50(table: pd.DataFrame, out=None, *, conditions=None, mark_mtf50: float | None = None,
              title: str | None = None, axis: str = "sensor"):
    """SPM of AP over (distance, camera MTF50), one panel per condition.

    ``table``: the sweep table (columns ``condition, mtf50_cy_per_mm, distance_m, ap``, and
    ``mtf50_cy_per_mrad`` for ``axis="angular"``). ``axis``: :data:`MTF50_AXES` (see
    :func:`mtf50_axis`). ``mark_mtf50`` draws the dashed OD50 guide at that MTF50, in the
    axis' unit (the paper uses 100 cy/mm).
    """
    column, label, _ = MTF50_AXES[axis]
    _require(table, ("condition", column, "distance_m", "ap"))
    conditions = list(conditions) if conditions is not None else list(dict.fromkeys(table["condition"]))
    fig, axes = plt.subplots(1, len(conditions), figsize=(5.2 * len(conditions), 4.2), squeeze=False,
                             constrained_layout=True)
    filled = None
    for ax, condition in zip(axes[0], conditions):
        part = table[table["condition"] == condition]
        if part.empty:
            raise ValueError(f"condition {condition!r} is not in the table (has: {', '.join(map(str, table['condition'].unique()))})")
        gx, gy, gz = interpolate_map(part["distance_m"], part[column], part["ap"])
        filled = _draw_map(ax, gx, gy, gz, part["distance_m"], part[column])
        if mark_mtf50 is not None and _mark_od50(ax, gx, gy, gz, mark_mtf50) is not None:
            ax.legend(loc="upper right", fontsize=7)
        ax.set(title=_label(condition), xlabel="distance (m)", ylabel=label)
    fig.colorbar(filled, ax=axes[0].tolist(), label="AP (COCO @[.5:.95], car)")
    if title:
        fig.suptitle(title)
    if out is not None:
        save_figure(fig, out)
    return fig


def spm_illuminance(table: pd.DataFrame, out=None, *, title: str | None = None):
    """SPM of AP over (distance, scene illuminance) for one camera (paper Fig. 8).

    ``table``: columns ``illuminance_lux`` (> 0; log axis), ``distance_m``, ``ap``; an
    illuminance sweep of one camera (a ``camera`` column, if present, must hold one value).
    """
    _require(table, ("illuminance_lux", "distance_m", "ap"))
    if "camera" in table and table["camera"].nunique() > 1:
        raise ValueError(f"spm_illuminance takes one camera, got {sorted(table['camera'].unique())}")
    gy, gx, gz = interpolate_map(table["illuminance_lux"], table["distance_m"], table["ap"], log_x=True)
    fig, ax = plt.subplots(figsize=(5.6, 4.2), constrained_layout=True)
    filled = _draw_map(ax, gx, gy, gz.T, table["distance_m"], table["illuminance_lux"])
    ax.set_yscale("log")
    ax.set(xlabel="distance (m)", ylabel="scene illuminance (lux)",
           title=title or (f"{table['camera'].iloc[0]}" if "camera" in table else "AP vs illuminance"))
    fig.colorbar(filled, ax=ax, label="AP (COCO @[.5:.95], car)")
    if out is not None:
        save_figure(fig, out)
    return fig


def fit_line(x, y) -> tuple[float, float]:
    """(slope, intercept) of the least-squares line through the finite points."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 2 or np.unique(x[ok]).size < 2:
        return float("nan"), float("nan")
    slope, intercept = np.polyfit(x[ok], y[ok], 1)
    return float(slope), float(intercept)


def od50_vs_mtf50(od50_table: pd.DataFrame, out=None, *, conditions=None, title: str | None = None,
                  measured_range_m: tuple[float, float] | None = None, axis: str = "sensor"):
    """OD50 against MTF50, per condition, with a fitted line whose slope (m per cycle/mm, or
    per cycle/mrad on the ``angular`` axis: :data:`MTF50_AXES`, :func:`mtf50_axis`) is in the
    legend (paper Fig. 7A). Error bars are the 95 % bootstrap interval when the
    table has it (``ci95_lo_m``, ``ci95_hi_m``): OD50 extrapolated beyond the measured
    distances has a skewed, unbounded spread that a symmetric ± SD bar misdraws (below
    0 m); an unbounded upper end is drawn to the top of the axes. Otherwise ± SD.

    ``od50_table``: columns ``condition, mtf50_cy_per_mm, od50_m, sd_m`` (``od50.csv``).
    Infinite OD50s (AP never falls to 0.5) are left out of the plot and the fit.
    ``measured_range_m`` (nearest, farthest distance, m): OD50s outside it are
    extrapolations (the paper's outlier, Fig. 7A); they are drawn hollow, at the top of
    the axes when they lie above it, and left out of the fit, so that one camera whose AP
    never falls to 0.5 in the measured range cannot set the slope. With ``censored`` and
    ``bound_m`` columns (:func:`benchmark.experiments.sweep.with_censoring`, as the report passes) the
    censored OD50s are drawn as hollow triangles at their bound instead — ▲ at the farthest
    distance ("> 200 m", a lower bound), ▼ at the nearest ("< 25 m") — and the legend says so.

    The OD50 axis is scaled to what is drawn (:func:`_axis_top_m`): the fitted OD50s, the
    bounds and the measured distances, never the extrapolated number behind a bound.

    With an ``n_environments`` column, OD50s from fewer than
    :data:`benchmark.scoring.MIN_ENVIRONMENTS` environments are drawn but not fitted: no line is
    drawn through a sample too small for a verdict (docs/scoring.md), and the legend says so.
    """
    x, x_label, x_unit = MTF50_AXES[axis]
    _require(od50_table, ("condition", x, "od50_m", "sd_m"))
    conditions = list(conditions) if conditions is not None else list(dict.fromkeys(od50_table["condition"]))
    lo_m, hi_m = measured_range_m if measured_range_m is not None else (-np.inf, np.inf)
    finite = od50_table.assign(od50_m=od50_table["od50_m"].astype(float))
    finite = finite[np.isfinite(finite["od50_m"])]
    censored = "censored" in finite.columns and "bound_m" in finite.columns
    if censored:  # a censored OD50 is a bound, drawn at the bound (not at its extrapolated number), not fitted
        finite = finite.assign(censored=finite["censored"].fillna("").astype(str))
        finite = finite.assign(fitted=finite["censored"] == "")
    else:
        finite = finite.assign(fitted=finite["od50_m"].between(lo_m, hi_m))
    inside = finite[finite["fitted"]]
    bounds = finite.loc[~finite["fitted"], "bound_m"] if censored else pd.Series(dtype=float)
    top = _axis_top_m(finite, inside, bounds, hi_m)
    fig, ax = plt.subplots(figsize=(5.6, 4.2), constrained_layout=True)
    for k, condition in enumerate(conditions):
        part = finite[finite["condition"] == condition]
        fitted, outside = part[part["fitted"]], part[~part["fitted"]]
        colour = CONDITION_COLOURS.get(condition, f"C{k}")
        few = _too_few(fitted)
        slope, intercept = fit_line(fitted.loc[~few, x], fitted.loc[~few, "od50_m"])
        name = _label(condition)
        label = f"{name}: slope {slope:.2f} m per {x_unit}" if np.isfinite(slope) else f"{name}: no fit"
        if few.any():  # (the page says why beside the table: benchmark.scoring.sample_too_small_text)
            label += f" ({few.sum()} from too few environments: not fitted)"
        if len(outside) and censored:
            label += f" ({_bounds_text(outside)}: hollow, not fitted)"
        elif len(outside):
            label += f" ({len(outside)} extrapolated: hollow, not fitted)"
        if censored and len(outside):
            for sign, marker in ((">", "^"), ("<", "v")):
                pts = outside[outside["censored"] == sign]
                if len(pts):
                    ax.plot(pts[x], np.minimum(pts["bound_m"].astype(float), top), marker, ms=8,
                            mfc="none", color=colour, alpha=0.9, ls="none")
            outside = outside.iloc[0:0]
        # filled (and labelled) even when empty, so every condition has its legend entry
        for points, style in ((fitted, {"label": label}), (outside, {"mfc": "none", "alpha": 0.8})):
            if len(points) or "label" in style:
                ax.errorbar(points[x], np.minimum(points["od50_m"], top),
                            yerr=_error_bars(points, top), fmt="o", color=colour, capsize=3, **style)
        if np.isfinite(slope):
            xs = np.linspace(fitted.loc[~few, x].min(), fitted.loc[~few, x].max(), 2)
            ax.plot(xs, slope * xs + intercept, "-", color=colour, lw=1.2)
    interval = {"ci95_lo_m", "ci95_hi_m"} <= set(od50_table.columns)
    ax.set(xlabel=x_label, ylabel="OD50 (m)", ylim=(0, top),
           title=title or ("OD50 vs MTF50 (95 % bootstrap interval)" if interval else "OD50 vs MTF50 (± bootstrap SD)"))
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    if out is not None:
        save_figure(fig, out)
    return fig


def _too_few(points: pd.DataFrame) -> pd.Series:
    """Per point: True where its OD50 rests on too few environments to be fitted (:func:`benchmark.scoring.too_few`)."""
    from benchmark.scoring import too_few

    if "n_environments" not in points.columns:
        return pd.Series(False, index=points.index)
    return points["n_environments"].map(too_few).astype(bool)


def _bounds_text(points: pd.DataFrame) -> str:
    """"2 OD50 > 200 m (▲, lower bounds), 1 < 25 m (▼)" of the censored points."""
    parts = []
    for sign, arrow, what in ((">", "▲", "lower bound"), ("<", "▼", "upper bound")):
        pts = points[points["censored"] == sign]
        if len(pts):
            parts.append(f"{len(pts)} OD50 {sign} {pts['bound_m'].astype(float).iloc[0]:g} m ({arrow}, {what}{'s' if len(pts) > 1 else ''})")
    return ", ".join(parts)


def _axis_top(table: pd.DataFrame) -> float:
    finite = table["od50_m"].astype(float)
    finite = finite[np.isfinite(finite)]
    return 1.6 * float(finite.max()) if finite.size and finite.max() > 0 else 1.0


def _axis_top_m(finite: pd.DataFrame, fitted: pd.DataFrame, bounds: pd.Series, farthest_m: float) -> float:
    """Top of the OD50 axis, m, from what the plot draws at its value: 1.6 × the largest
    fitted OD50, 1.15 × the largest censored bound (its ▲ stays inside), 1.1 × the farthest
    measured distance. An OD50 extrapolated behind a bound ("> 200 m" whose number is 1300 m)
    never sets the scale; with no fitted point, bound or measured range known, every point
    is drawn at its value and sets it."""
    tops = [_axis_top(fitted)] if len(fitted) else []
    bounds = bounds.astype(float)
    tops += [1.15 * float(b) for b in bounds[np.isfinite(bounds)]]
    if np.isfinite(farthest_m):
        tops.append(1.1 * farthest_m)
    return max(tops) if tops else _axis_top(finite)


def _error_bars(part: pd.DataFrame, top: float) -> np.ndarray:
    """(2, n) lower/upper bar lengths: the 95 % interval if present, else ± SD; OD50 and
    interval clipped to the top of the axes."""
    od50 = np.minimum(part["od50_m"].astype(float).to_numpy(), top)
    if {"ci95_lo_m", "ci95_hi_m"} <= set(part.columns):
        lo = np.minimum(np.clip(part["ci95_lo_m"].astype(float).to_numpy(), 0.0, None), od50)
        hi = np.minimum(part["ci95_hi_m"].astype(float).to_numpy(), top)
        return np.nan_to_num(np.stack([od50 - lo, np.maximum(hi - od50, 0.0)]))
    sd = part["sd_m"].astype(float).fillna(0.0).to_numpy()
    return np.stack([np.minimum(sd, od50), sd])


def _require(table: pd.DataFrame, columns) -> None:
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise ValueError(f"table lacks column(s) {missing} (has: {list(table.columns)})")
    if table.empty:
        raise ValueError("table is empty")
