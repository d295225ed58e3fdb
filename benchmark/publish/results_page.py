"""The tables of docs/results.md, made from docs/data rather than typed (``benchmark publish markdown``).

AP per distance with Spearman's ρ and OD50 per condition, the nights side by side, the
input-size comparison, the acquisition policies, the illuminance sweep, ``day_paper`` and the
night factors: those a folder holds (metric-300 has no native or policy sweeps). With
``against``, another collection's folder: each condition's OD50s camera by camera in both, with
SDs and ranks (metric-300 against quick).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from benchmark.experiments.acceptance import ap_distance_rho
from benchmark.experiments.sweep import od50_cell, with_censoring
from benchmark.publish.sweep_tables import POLICY_CONDITIONS, REFERENCE_POLICY
from benchmark.scoring.ap_range import ap_range
from benchmark.scoring.od50 import od50_rank_value

NIGHTS = ("night", "night_regulation")  # the paper's night, then the unlit regulation road


def _minus(text: str) -> str:
    return text.replace("-", "−")


def _od50_text(row, *, whole_metres: bool = False) -> str:
    """OD50 ± SD, the bound when censored, or the 95 % interval where the SD exceeds half the OD50."""
    if not row.get("censored") and np.isfinite(row["od50_m"]) and row["sd_m"] > row["od50_m"] / 2:
        hi = "∞" if np.isinf(row["ci95_hi_m"]) else f"{row['ci95_hi_m']:.0f}"  # (resamples that never fall to 0.5)
        return f"{row['od50_m']:.0f} (95 %: {row['ci95_lo_m']:.0f}–{hi})"
    return _od50_metres(row) if whole_metres else od50_cell(row)


def _od50_metres(row, *, sd: bool = True) -> str:
    """OD50 in whole metres (± SD), or its bound when censored."""
    if row.get("censored"):
        return od50_cell(row)
    return f"{row['od50_m']:.0f} ± {row['sd_m']:.0f}" if sd else f"{row['od50_m']:.0f}"


def _row(cells) -> str:
    return "| " + " | ".join(cells) + " |"


def _rule(n: int) -> str:
    return "|" + "---|" * n


def ap_table(table: pd.DataFrame, od50: pd.DataFrame, condition: str) -> str:
    """camera | MTF50 | AP per distance | Spearman ρ | OD50, one condition."""
    rows = table[table["condition"] == condition]
    distances = sorted(rows["distance_m"].unique())
    rho = ap_distance_rho(table, condition)
    lines = [_row(["camera", "MTF50", *(f"{d:g} m" for d in distances), "Spearman ρ", "OD50 (m)"]),
             _rule(len(distances) + 4)]
    od50 = od50[od50["condition"] == condition].set_index("camera")
    for camera, part in rows.groupby("camera"):
        ap = part.set_index("distance_m")["ap"]
        r = rho.get(camera, np.nan)
        lines.append(_row([camera, f"{part['mtf50_cy_per_mm'].iloc[0]:.1f}", *(f"{ap[d]:.2f}" for d in distances),
                           "—" if np.isnan(r) else _minus(f"{r:.2f}"), _od50_text(od50.loc[camera])]))
    return "\n".join(lines)


def input_size_table(data: Path) -> str:
    """OD50 and ρ by day under the three input-size policies."""
    sides = {name: _load(data, suffix) for name, suffix in (("native", "-native"), ("640", "-640"), ("multiscale", ""))}
    lines = [_row(["camera", "MTF50", *(f"OD50 {n} (m)" for n in sides), *(f"ρ {n}" for n in sides)]),
             _rule(8)]
    rhos = {n: ap_distance_rho(t, "day") for n, (t, _) in sides.items()}
    day = {n: o[o["condition"] == "day"].set_index("camera") for n, (_, o) in sides.items()}
    for camera, row in day["multiscale"].iterrows():
        cells = [_od50_metres(d.loc[camera], sd=False) for d in day.values()]
        lines.append(_row([camera, f"{row['mtf50_cy_per_mm']:.1f}", *cells,
                           *(_minus(f"{rhos[n][camera]:.2f}") for n in sides)]))
    return "\n".join(lines)


def policy_tables(data: Path) -> str:
    """AP at 25 m / AP at 50 m / OD50 ± SD per camera and policy, dusk then night."""
    table = pd.read_csv(data / "sweep-policies.csv")
    od50 = pd.read_csv(data / "od50-policies.csv")
    policies = list(dict.fromkeys(table["exposure"]))
    out = []
    for condition in POLICY_CONDITIONS:
        header = [p.replace("auto_peak", "`auto_peak`") if p == REFERENCE_POLICY else f"`{p}`" for p in policies]
        lines = [_row(["camera", *header]), _rule(len(policies) + 1)]
        for camera in dict.fromkeys(table.loc[table["exposure"] != REFERENCE_POLICY, "camera"]):
            first = table[table["camera"] == camera].iloc[0]
            cells = [f"{camera} ({first['pixel_um']:g} µm, f/{first['f_number']:g})"]
            for policy in policies:
                part = table[(table["camera"] == camera) & (table["condition"] == condition) & (table["exposure"] == policy)]
                ap = part.set_index("distance_m")["ap"]
                o = od50[(od50["camera"] == camera) & (od50["condition"] == condition) & (od50["exposure"] == policy)]
                cell = _od50_metres(with_censoring(o, part).iloc[0])
                cells.append(f"{ap[25.0]:.2f} / {ap[50.0]:.2f} / {cell}")
            lines.append(_row(cells))
        out.append(f"{condition}:\n\n" + "\n".join(lines))
    return "\n\n".join(out)


def illuminance_table(data: Path) -> str:
    """AP at 25 and 50 m and OD50 per illuminance level."""
    table, od50 = _load(data, "-illuminance")
    levels = list(dict.fromkeys(table["condition"]))
    lux = [c.split("@")[1].removesuffix("lux") for c in levels]
    od50 = od50.set_index("condition")
    lines = [_row(["illuminance (lux)", *lux]), _rule(len(lux) + 1)]
    for d in (25.0, 50.0):
        ap = table[table["distance_m"] == d].set_index("condition")["ap"]
        lines.append(_row([f"AP at {d:g} m", *(f"{ap[c]:.2f}" for c in levels)]))
    lines.append(_row(["OD50 (m)", *(_od50_text(od50.loc[c], whole_metres=True) for c in levels)]))
    return "\n".join(lines)


def _load(data: Path, suffix: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    table = pd.read_csv(data / f"sweep{suffix}.csv")
    return table, with_censoring(pd.read_csv(data / f"od50{suffix}.csv"), table)


def day_paper_table(data: Path) -> str:
    """OD50 by day against the paper's 10-200 lux day (``day_paper``): the difference in SDs."""
    table, od50 = _load(data, "")
    paper_table, paper = _load(data, "-day-paper")
    day = od50[od50["condition"] == "day"].set_index("camera")
    lines = [_row(["camera", "OD50 day (m)", "OD50 day_paper (m)", "difference / SD"]), _rule(4)]
    for camera, row in paper.set_index("camera").iterrows():
        ref = day.loc[camera]
        both = np.hypot(ref["sd_m"], row["sd_m"])
        diff = (row["od50_m"] - ref["od50_m"]) / both if both > 0 else np.nan
        lines.append(_row([camera, _od50_metres(ref), _od50_metres(row),
                           "—" if not np.isfinite(diff) else _minus(f"{diff:.1f}")]))
    return "\n".join(lines)


def three_nights_table(data: Path) -> str:
    """Per camera, the paper's night and the regulation night side by side: AP at 25 and 50 m
    and OD50 in each, with the day OD50 for scale."""
    table, od50 = _load(data, "")
    od50 = od50.set_index(["camera", "condition"])
    lines = [_row(["camera", "MTF50", "OD50 day (m)", "paper's night: AP 25 m / 50 m", "paper's night: OD50 (m)",
                   "regulation night: AP 25 m / 50 m", "regulation night: OD50 (m)"]), _rule(7)]
    for camera, part in table.groupby("camera"):
        ap = part.set_index(["condition", "distance_m"])["ap"]
        cells = [camera, f"{part['mtf50_cy_per_mm'].iloc[0]:.1f}", _od50_metres(od50.loc[(camera, "day")])]
        for night in NIGHTS:
            cells += [f"{ap[(night, 25.0)]:.2f} / {ap[(night, 50.0)]:.2f}", _od50_metres(od50.loc[(camera, night)])]
        lines.append(_row(cells))
    return "\n".join(lines)


def night_factors_table(data: Path) -> str:
    """docs/data/night-factors.csv's rows (:mod:`benchmark.publish.night_factors`): one change at a time at the paper's night's lux."""
    rows = pd.read_csv(data / "night-factors.csv")
    ap_cols = [c for c in rows.columns if c.startswith("ap_")]
    lines = [_row(["camera", "factor", "change", "image-plane lux", "exposure (ms)", "car e⁻", "frame e⁻",
                   *(f"AP {c[3:]}" for c in ap_cols)]), _rule(7 + len(ap_cols))]
    for _, r in rows.iterrows():
        lines.append(_row([r["camera"], r["factor"], r["variant"], f"{r['image_plane_lux']:.2f}", f"{r['exposure_ms']:.1f}",
                           f"{r['car_median_e']:.1f}", f"{r['frame_mean_e']:.1f}", *(f"{r[c]:.2f}" for c in ap_cols)]))
    return "\n".join(lines)


def rank_value(row, ap: pd.Series) -> float:
    """A row of :func:`_load`'s od50 table (its ``censored`` and ``bound_m``) to rank by, by the
    leaderboard's rule (:func:`benchmark.scoring.od50.od50_rank_value`; ``ap``: the camera's AP by distance)."""
    bound = float(row["bound_m"]) if row["censored"] else None
    return od50_rank_value(row["od50_m"], row["censored"], bound,
                           ap_range_m=ap_range(list(ap.index), list(ap.values)))


def collections_table(loaded: list[tuple[pd.DataFrame, pd.DataFrame]], names: tuple[str, str], condition: str) -> str:
    """One condition's OD50s in this folder's collection against another's (metric-300 against
    quick): each with its bootstrap SD, the SD ratio and the difference in units of the two SDs
    combined where both are measured (different scenes: unpaired), each camera's rank in each;
    then Spearman's ρ of the two orders. ``loaded``: :func:`_load` of the other folder, then this one."""
    from scipy import stats

    tables = [od50[od50["condition"] == condition].set_index("camera") for _, od50 in loaded]
    cameras = [c for c in tables[0].index if c in tables[1].index]  # (ranked among the cameras both hold)
    sides = []
    for (table, _), od50 in zip(loaded, tables):
        ap = table[table["condition"] == condition].set_index(["camera", "distance_m"])["ap"]
        value = pd.Series({camera: rank_value(od50.loc[camera], ap[camera]) for camera in cameras})
        sides.append((od50, value.rank(ascending=False, method="min").astype(int)))
    (a, rank_a), (b, rank_b) = sides
    lines = [_row(["camera", "MTF50", f"OD50 {names[0]} (m)", f"OD50 {names[1]} (m)", "SD ratio", "difference / SD",
                   f"rank {names[0]} → {names[1]}"]), _rule(7)]
    for camera in sorted(cameras, key=lambda c: rank_b[c]):
        ra, rb = a.loc[camera], b.loc[camera]
        measured = not ra["censored"] and not rb["censored"]
        both = np.hypot(ra["sd_m"], rb["sd_m"])
        lines.append(_row([camera, f"{rb['mtf50_cy_per_mm']:.1f}", _od50_metres(ra), _od50_metres(rb),
                           f"{rb['sd_m'] / ra['sd_m']:.2f}" if measured and ra["sd_m"] > 0 else "—",
                           _minus(f"{(rb['od50_m'] - ra['od50_m']) / both:.1f}") if measured and both > 0 else "—",
                           f"{rank_a[camera]} → {rank_b[camera]}"]))
    rho = stats.spearmanr(rank_a[cameras], rank_b[cameras]).statistic
    return "\n".join(lines) + f"\n\nSpearman's ρ of the two orders ({len(cameras)} cameras): {_minus(f'{rho:.2f}')}"


def mtf50_rho_table(table: pd.DataFrame, od50: pd.DataFrame) -> str:
    """Per condition, Spearman's ρ across cameras of the OD50 against MTF50 (cy/mrad, in object
    space): over the cameras whose OD50 is measured inside the distances, and over every camera
    by the leaderboard's rank value (a censored OD50 by its tier and AP range); then ρ of the AP
    range (area under AP vs distance) against MTF50, every camera."""
    from benchmark.experiments.acceptance import _spearman

    lines = [_row(["condition", "cameras", "OD50 measured", "ρ(OD50, MTF50), measured", "ρ(rank value, MTF50)",
                   "ρ(AP range, MTF50)"]), _rule(6)]
    for condition in [c for c in ("day", "dusk", *NIGHTS) if c in set(od50["condition"])]:
        rows = od50[od50["condition"] == condition].set_index("camera")
        ap = table[table["condition"] == condition].set_index(["camera", "distance_m"])["ap"]
        measured = rows[(rows["censored"] == "") & np.isfinite(rows["od50_m"])]
        value = pd.Series({camera: rank_value(rows.loc[camera], ap[camera]) for camera in rows.index})
        ranges = pd.Series({camera: ap_range(list(ap[camera].index), list(ap[camera].values)) for camera in rows.index})
        mtf = rows["mtf50_cy_per_mrad"]
        rhos = (_spearman(measured["mtf50_cy_per_mrad"], measured["od50_m"]), _spearman(mtf, value[mtf.index]),
                _spearman(mtf, ranges[mtf.index]))
        lines.append(_row([condition, str(len(rows)), str(len(measured)),
                           *("—" if np.isnan(rho) else _minus(f"{rho:.2f}") for rho in rhos)]))
    return "\n".join(lines)


def tables(data: Path, against: Path | None = None, names: tuple[str, str] = ("quick", "metric-300")) -> dict[str, str]:
    """The tables of docs/results.md that ``data`` (and ``against``) hold, by their headings."""
    table, od50 = _load(data, "")
    parts = {c: ap_table(table, od50, c) for c in ("day", "dusk", *NIGHTS) if c in set(table["condition"])}
    if set(NIGHTS) <= set(table["condition"]):
        parts["the nights side by side"] = three_nights_table(data)
    parts["OD50 against MTF50"] = mtf50_rho_table(table, od50)
    if (data / "od50-native.csv").exists() and (data / "od50-640.csv").exists():
        parts["input size (day)"] = input_size_table(data)
    if (data / "od50-policies.csv").exists():
        parts["policies"] = policy_tables(data)
    if (data / "od50-illuminance.csv").exists():
        parts["illuminance"] = illuminance_table(data)
    if (data / "od50-day-paper.csv").exists():
        parts["day_paper"] = day_paper_table(data)
    if (data / "night-factors.csv").exists():
        parts["night factors"] = night_factors_table(data)
    if against is not None:
        loaded = [_load(against, ""), (table, od50)]
        shared = [c for c in ("day", "dusk", *NIGHTS) if c in set(table["condition"]) and c in set(loaded[0][0]["condition"])]
        parts |= {f"{c}: {names[1]} against {names[0]}": collections_table(loaded, names, c) for c in shared}
    return parts


def markdown(data: Path, against: Path | None = None, names: tuple[str, str] = ("quick", "metric-300")) -> str:
    """``tables`` as markdown, each under its ``###`` heading."""
    return "\n\n".join(f"### {heading}\n\n{text}" for heading, text in tables(data, against, names).items())
