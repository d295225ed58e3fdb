"""The references' band: per condition and distance, the lowest, median and highest AP of a
protocol's reference submissions (:meth:`Protocol.is_reference`), from their ``per_distance``
AP alone (no detections needed, so the references made before detections shipped draw it too).

The leaderboard page draws it per protocol (:func:`band_svg`, inline SVG written by hand: the same
submissions give the same bytes); ``benchmark report RUN --references PROTOCOL`` draws a run's AP
vs distance over it (:func:`benchmark.experiments.report.plot_over_band`).
"""

from __future__ import annotations

import html
import statistics
from dataclasses import dataclass
from pathlib import Path

from benchmark.leaderboard.protocols import Protocol


@dataclass(frozen=True)
class ConditionBand:
    condition: str
    distances_m: tuple[float, ...]
    lo: tuple[float, ...]  # lowest AP of the references at each distance
    median: tuple[float, ...]
    hi: tuple[float, ...]
    n: int  # references behind it


def reference_band(submissions: list[dict], protocol: Protocol, *, manifest_sha256: str | None = None) -> list[ConditionBand]:
    """The band of ``protocol``'s references among ``submissions`` (those of one manifest where
    ``manifest_sha256`` is given), one per condition of the protocol that a reference reports, in
    the protocol's order; [] where it has none."""
    refs = [s for s in submissions if s["collection"]["protocol"] == protocol.name and protocol.is_reference(s["name"])
            and (manifest_sha256 is None or s["collection"]["manifest_sha256"] == manifest_sha256)]
    out = []
    for condition in protocol.conditions:
        curves = [{float(r["distance_m"]): float(r["ap"]) for r in s["conditions"][condition]["per_distance"]}
                  for s in refs if condition in s["conditions"]]
        if not curves:
            continue
        distances = tuple(d for d in protocol.distances_m if all(d in c for c in curves))
        values = [[c[d] for c in curves] for d in distances]
        out.append(ConditionBand(condition, distances, tuple(min(v) for v in values),
                                 tuple(statistics.median(v) for v in values), tuple(max(v) for v in values), len(curves)))
    return out


def references_of(protocol_name: str, leaderboard_dir: str | Path, *, manifest_sha256: str | None = None) -> tuple[Protocol, list[ConditionBand]]:
    """(protocol, band) of a leaderboard folder's references of ``protocol_name`` (every
    submission validated first: :func:`benchmark.leaderboard.folder.load_submissions`)."""
    from benchmark.leaderboard.protocols import load_protocols
    from benchmark.leaderboard.folder import load_submissions

    if not Path(leaderboard_dir).is_dir():
        raise ValueError(f"--references: no leaderboard folder {leaderboard_dir} (name one with --leaderboard)")
    protocols = load_protocols(leaderboard_dir)
    protocol = protocols.get(protocol_name)
    if protocol is None:
        raise ValueError(f"--references {protocol_name}: not a protocol of {leaderboard_dir} (protocols: {', '.join(protocols)})")
    if protocol.references is None:
        raise ValueError(f"--references {protocol_name}: the protocol names no references (protocols.yaml 'references')")
    band = reference_band(load_submissions(leaderboard_dir, protocols), protocol, manifest_sha256=manifest_sha256)
    if not band:
        on = f" on manifest {manifest_sha256[:12]}..." if manifest_sha256 else ""
        raise ValueError(f"--references {protocol_name}: no reference submission ({protocol.references}){on} in {leaderboard_dir}")
    return protocol, band


# The page's figure: one panel per condition, AP 0-1 over the protocol's distances.
PANEL_W, PANEL_H, LEFT, RIGHT, TOP, BOTTOM = 300, 190, 40, 12, 26, 34
BAND_FILL, MEDIAN_STROKE, GRID = "#9ecae1", "#08519c", "#bbbbbb"


def _f(x: float) -> str:
    return f"{x:.1f}"


def band_svg(band: list[ConditionBand], protocol: Protocol) -> str:
    """The band as one SVG (a panel per condition: min-max shaded, the median a line, AP 0.5
    dotted), titled by each condition's label; presentation attributes only (no style: the
    page's Content-Security-Policy allows its own stylesheet alone)."""
    esc = html.escape
    d_min, d_max = min(protocol.distances_m), max(protocol.distances_m)
    width, height = PANEL_W * len(band), PANEL_H
    n = max(b.n for b in band)
    title = f"AP vs distance of the {n} references of {protocol.name}: lowest to highest (band) and median (line)"
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width} {height}" width="{width}" height="{height}" '
           f'role="img" aria-label="{esc(title)}" font-family="sans-serif" font-size="10">', f"<title>{esc(title)}</title>"]
    for k, b in enumerate(band):
        x0, x1 = k * PANEL_W + LEFT, (k + 1) * PANEL_W - RIGHT
        y0, y1 = TOP, PANEL_H - BOTTOM

        def x(d: float) -> float:
            return x0 + (d - d_min) / (d_max - d_min) * (x1 - x0)

        def y(ap: float) -> float:
            return y1 - ap * (y1 - y0)

        out.append(f'<g data-condition="{esc(b.condition)}">')
        out.append(f'<text x="{_f((x0 + x1) / 2)}" y="{TOP - 10}" text-anchor="middle" font-size="11" '
                   f'font-weight="bold">{esc(protocol.label(b.condition))}</text>')
        out.append(f'<rect x="{_f(x0)}" y="{_f(y0)}" width="{_f(x1 - x0)}" height="{_f(y1 - y0)}" fill="none" stroke="{GRID}"/>')
        for ap in (0.0, 0.5, 1.0):
            out.append(f'<text x="{_f(x0 - 4)}" y="{_f(y(ap) + 3)}" text-anchor="end">{ap:g}</text>')
        out.append(f'<line x1="{_f(x0)}" y1="{_f(y(0.5))}" x2="{_f(x1)}" y2="{_f(y(0.5))}" stroke="#777777" '
                   'stroke-dasharray="2 3"/>')
        for d in protocol.distances_m:
            out.append(f'<text x="{_f(x(d))}" y="{_f(y1 + 13)}" text-anchor="middle">{d:g}</text>')
        out.append(f'<text x="{_f((x0 + x1) / 2)}" y="{PANEL_H - 4}" text-anchor="middle">distance (m) · '
                   f'{b.n} references</text>')
        if k == 0:
            out.append(f'<text x="10" y="{_f((y0 + y1) / 2)}" text-anchor="middle" '
                       f'transform="rotate(-90 10 {_f((y0 + y1) / 2)})">AP</text>')
        upper = [f"{_f(x(d))},{_f(y(v))}" for d, v in zip(b.distances_m, b.hi)]
        lower = [f"{_f(x(d))},{_f(y(v))}" for d, v in zip(b.distances_m, b.lo)]
        out.append(f'<polygon points="{" ".join(upper + lower[::-1])}" fill="{BAND_FILL}" fill-opacity="0.7" '
                   f'stroke="{BAND_FILL}"/>')
        median = " ".join(f"{_f(x(d))},{_f(y(v))}" for d, v in zip(b.distances_m, b.median))
        out.append(f'<polyline points="{median}" fill="none" stroke="{MEDIAN_STROKE}" stroke-width="1.5"/>')
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"
