"""Render the leaderboard (``README.md`` and ``index.html``) from ``submissions/*.json``.

Deterministic: the output depends only on the submissions (and the accepted protocols):
rows are ranked by daylight OD50, then night OD50 (missing = last), then name, a censored OD50
by its tier and the AP range (:func:`od50_sort_value`); the only date shown is the newest
submission's ``created_at``. OD50 and AP range from fewer than
:data:`benchmark.scoring.MIN_ENVIRONMENTS` environments carry :data:`benchmark.scoring.FEW_MARK`. Both files are written atomically
(:func:`metricscenes.files.write_atomic`) and only after every submission
has validated, so a bad submission or an interrupted render leaves the old table intact.

Columns and figures name each condition by what it physically is (:meth:`Protocol.label`). Under
each protocol's table the references' band (:mod:`benchmark.leaderboard.band`): inline SVG in the
page, ``references-<protocol>.svg`` beside README.md.

The HTML page is self-contained: inline CSS and a small vanilla-JS sorter, allowed by a
Content-Security-Policy that names their sha256 and nothing else (no external URLs).
Clicking a column header sets ``#sort=<key>`` (``#sort=-<key>``: descending) and the
tables sort on ``hashchange``, so a sorted view is a link (and testable headlessly).
"""

from __future__ import annotations

import base64
import hashlib
import html
import math
import re
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from benchmark.leaderboard.band import band_svg, reference_band
from benchmark.leaderboard.folder import load_submissions
from benchmark.leaderboard.protocols import Protocol, load_protocols
from benchmark.scoring.sample import few_footnote
from benchmark.leaderboard.validate import SUBMISSIONS, duplicate_problem, read_submission_file, validate_submission
from metricscenes.files import write_atomic

REPRODUCE = """\
for c in quick adas-quick metric-300; do  # metric-300 takes hours on 2 cores (docs/performance.md)
  metricscenes generate --manifest manifests/$c.yaml --out collections/$c
  benchmark sweep --collection collections/$c --conditions day,dusk,night,night_regulation --model yolov5n-dynamic \\
      --out sweeps/$c --no-save-images
  benchmark submit sweeps/$c --name "ref-{camera}-yolov5n-$c" --submitter 'metricscenes reference'
done
benchmark leaderboard"""


@dataclass(frozen=True)
class Column:
    key: str
    header: str
    kind: str  # "num" | "str": how the page sorts it


def censoring(cond: dict) -> tuple[str, float | None, float | None]:
    """(``censored``, ``bound_m``, AP at the bound) of one condition entry, from its per-distance AP
    (:func:`benchmark.scoring.od50_censoring`): ">" when AP has not fallen to 0.5 at the farthest
    distance (the stored OD50 is an extrapolation, or null), "<" when it is below 0.5 already at
    the nearest, "" when the crossing was measured."""
    from benchmark.scoring.od50 import od50_censoring

    rows = [r for r in cond.get("per_distance") or [] if r.get("ap") is not None and math.isfinite(float(r["ap"]))]
    if len(rows) < 2:
        return ("", None, None) if cond["od50_m"] is not None else (">", None, None)
    censored, bound = od50_censoring([r["distance_m"] for r in rows], [r["ap"] for r in rows])
    if not censored:
        return "", None, None
    at = next(float(r["ap"]) for r in rows if float(r["distance_m"]) == bound)
    return censored, bound, at


def ap_range_of(cond: dict | None) -> float | None:
    """The AP range (m) of one condition entry from its per-distance AP
    (:func:`benchmark.scoring.ap_range`); None: absent, or no finite AP."""
    from benchmark.scoring import ap_range

    rows = [r for r in (cond or {}).get("per_distance") or [] if r.get("ap") is not None and math.isfinite(float(r["ap"]))]
    return ap_range([r["distance_m"] for r in rows], [r["ap"] for r in rows]) if rows else None


def od50_sort_value(cond: dict | None) -> float | None:
    """The number a condition is ranked by (higher is better; None: absent):
    :func:`benchmark.scoring.od50.od50_rank_value` of its OD50, censored from its per-distance AP,
    a censored one ranked within its tier by the AP range (:func:`ap_range_of`)."""
    from benchmark.scoring.od50 import od50_rank_value

    if cond is None:
        return None
    censored, bound, _ = censoring(cond)
    return od50_rank_value(cond["od50_m"], censored, bound, ap_range_m=ap_range_of(cond))


def rank_key(sub: dict) -> tuple:
    """Sort key: daylight OD50 descending, then night OD50 descending (absent last), then name;
    censored OD50s rank by :func:`od50_sort_value`."""
    day = od50_sort_value(sub["conditions"].get("day"))
    night = od50_sort_value(sub["conditions"].get("night"))
    return (-(day if day is not None else -math.inf), -(night if night is not None else -math.inf), sub["name"])


def ranked(submissions: list[dict]) -> list[dict]:
    return sorted(submissions, key=rank_key)


def _fmt_od50(cond: dict | None) -> tuple[str, str]:
    """(sort value, text) of one condition's OD50 ± SD; censored: the bound ("> 200", "< 25"),
    no ±, and :func:`od50_sort_value` as sort value (never the extrapolated number)."""
    from benchmark.scoring import mark_few

    if cond is None:
        return "", "–"
    censored, bound, _ = censoring(cond)
    if censored:
        value = od50_sort_value(cond)
        text = f"{censored} {bound:g}" if bound is not None else "∞"
        return ("Infinity" if value == math.inf else repr(float(value))), mark_few(text, cond.get("n_environments"))
    sd = cond["od50_sd_m"]
    text = f"{cond['od50_m']:.1f}" + (f" ± {sd:.1f}" if sd is not None else "")
    return repr(float(cond["od50_m"])), mark_few(text, cond.get("n_environments"))


def _fmt_ap_range(cond: dict | None) -> tuple[str, str]:
    """(sort value, text) of one condition's AP range (m), marked as the OD50 is."""
    from benchmark.scoring import mark_few

    value = ap_range_of(cond)
    if value is None:
        return "", "–"
    return repr(float(value)), mark_few(f"{value:.1f}", cond.get("n_environments"))


RANKED_CONDITIONS = ("day", "night")
"""The conditions the rank reads, in order; their AP range is shown beside the OD50s."""


def _few(submissions: list[dict]) -> bool:
    from benchmark.scoring import too_few

    return any(too_few(c.get("n_environments")) for s in submissions for c in s["conditions"].values())


def _resamples(submissions: list[dict]) -> str:
    counts = sorted({int(s["scoring"]["bootstrap_resamples"]) for s in submissions if "scoring" in s})
    return (" or ".join(map(str, counts)) + " resamples") if counts else "resamples"


def _num(value, fmt: str) -> tuple[str, str]:
    return ("", "–") if value is None else (repr(float(value)), format(value, fmt))


def _title(protocol: Protocol, condition: str) -> str:
    """A condition as a column header: what it physically is, capitalised ("Daylight")."""
    label = protocol.label(condition)
    return label[:1].upper() + label[1:]


def columns(protocol: Protocol) -> list[Column]:
    od50 = [Column(f"{c}_od50", f"{_title(protocol, c)} OD50 (m)", "num") for c in protocol.conditions]
    ranges = [Column(f"{c}_ap_range", f"{_title(protocol, c)} AP range (m)", "num") for c in RANKED_CONDITIONS
              if c in protocol.conditions]
    return [Column("rank", "#", "num"), Column("system", "System", "str"), Column("camera", "Camera", "str"), *od50, *ranges,
            Column("mtf50", "MTF50 (cy/mm)", "num"), Column("mtf50_mrad", "MTF50 (cy/mrad)", "num"),
            Column("focal_mm", "Focal (mm)", "num"), Column("fov", "FOV (°)", "num"),
            Column("pixel_um", "Pixel (µm)", "num"),
            Column("f_number", "f-number", "num"), Column("detector", "Detector", "str"),
            Column("submitter", "Submitter", "str"), Column("date", "Date", "str")]  # fmt: skip


def camera_geometry(spec: dict) -> tuple[float, float, float]:
    """(focal length mm, horizontal and vertical field of view in degrees) of a submission's
    camera spec (the spec's own geometry: distortion included)."""
    from benchmark.leaderboard.validate import camera_from_dump

    camera = camera_from_dump(spec)
    return camera.optics.focal_length_mm, camera.hfov_deg, camera.vfov_deg


def row_cells(rank: int, sub: dict, protocol: Protocol) -> dict[str, tuple[str, str]]:
    """``{column key: (sort value, text)}`` of one submission. MTF50 in cycles/mrad (object
    space: × focal length / 1000), focal length and field of view are derived from the
    submitted spec and MTF50, so every submission shows them."""
    from benchmark.camera.spec import cy_per_mrad

    spec = sub["camera"]["spec"]
    mtf = sub["camera"]["mtf50_cy_per_mm"]
    focal, hfov, vfov = camera_geometry(spec)
    cells = {"rank": (str(rank), str(rank)), "system": (sub["name"], sub["name"]), "camera": (sub["camera"]["name"],) * 2}
    for c in protocol.conditions:
        cells[f"{c}_od50"] = _fmt_od50(sub["conditions"].get(c))
        if c in RANKED_CONDITIONS:
            cells[f"{c}_ap_range"] = _fmt_ap_range(sub["conditions"].get(c))
    group = " (group)" if sub["camera"]["mtf50_source"] == "published_group" else ""
    mtf_sort, mtf_text = _num(mtf, ".0f")
    mrad_sort, mrad_text = _num(cy_per_mrad(mtf, focal), ".2f")
    cells.update({
        "mtf50": (mtf_sort, mtf_text + group),
        "mtf50_mrad": (mrad_sort, mrad_text + group),
        "focal_mm": _num(focal, "g"),
        "fov": (repr(float(hfov)), f"{hfov:.1f} × {vfov:.1f}"),
        "pixel_um": _num(spec["sensor"]["pixel_um"], "g"),
        "f_number": _num(spec["optics"]["f_number"], "g"),
        "detector": (sub["detector"]["name"],) * 2,
        "submitter": (sub["submitter"],) * 2,
        "date": (sub["created_at"], sub["created_at"][:10]),
    })  # fmt: skip
    return cells


def _by_protocol(submissions: list[dict], protocols: dict[str, Protocol]) -> list[tuple[Protocol, list[dict]]]:
    return [(p, ranked([s for s in submissions if s["collection"]["protocol"] == name])) for name, p in protocols.items()]


_SAFE_FILE = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,79}")


def band_file(protocol: Protocol) -> str | None:
    """``references-<protocol>.svg``, the band's file beside README.md (None: a name unfit for a file)."""
    return f"references-{protocol.name}.svg" if _SAFE_FILE.fullmatch(protocol.name) else None


def band_figures(submissions: list[dict], protocols: dict[str, Protocol]) -> dict[str, str]:
    """{protocol name: SVG of its references' band} for the protocols that have references."""
    out = {}
    for name, protocol in protocols.items():
        band = reference_band(submissions, protocol)
        if band:
            out[name] = band_svg(band, protocol)
    return out


def _band_caption(submissions: list[dict], protocol: Protocol) -> tuple[str, str]:
    """(text, command) under the band figure."""
    n = sum(1 for s in submissions if s["collection"]["protocol"] == protocol.name and protocol.is_reference(s["name"]))
    return (f"AP vs distance of the {n} references ({protocol.references}), per condition: shaded from the lowest to "
            "the highest AP, the line their median; dotted: AP 0.5. A run over it:",
            f"benchmark report RUN --references {protocol.name}")


# Markdown's inline syntax: a backslash before any of these shows it as itself (CommonMark
# "backslash escapes"), as html.escape does for the page; "|" would end the table cell.
_MD_SPECIAL = re.compile(r"([\\`*_{}\[\]<>|~&!#])")
_MD_BREAK = re.compile("[\x00-\x1f\x7f-\x9f\u2028\u2029]")  # line breaks and other controls: one table row


def _md(text: str) -> str:
    """``text`` shown as itself in a Markdown table cell: no links, images, HTML, emphasis or code."""
    return _MD_SPECIAL.sub(r"\\\1", _MD_BREAK.sub(" ", text))


def _ranked_labels(protocols: dict[str, Protocol]) -> tuple[str, str]:
    """What the two ranked conditions (day, night) physically are, for the page's prose."""
    from benchmark.leaderboard.protocols import condition_label

    labels = next(iter(protocols.values())).labels if protocols else None
    return tuple(condition_label(c, labels) for c in RANKED_CONDITIONS)  # type: ignore[return-value]


def render_markdown(submissions: list[dict], protocols: dict[str, Protocol]) -> str:
    latest = max((s["created_at"] for s in submissions), default=None)
    day, night = (_md(t) for t in _ranked_labels(protocols))
    lines = [
        "# metricscenes leaderboard", "",
        "<!-- Generated by `benchmark leaderboard` from submissions/; edits are overwritten. -->", "",
        "How far away does a camera system (camera + ISP + detector) still find a car? Each table ranks",
        f"systems by the OD50 in **{day}**, the distance at which COCO AP of the car falls to 0.5 (Liu et al.,",
        f"EI 2023), then by the OD50 in **{night}**. ± is the bootstrap SD over environments ({_resamples(submissions)}).",
        "Censored OD50s show a bound: \\> 200 when AP has not yet fallen to 0.5 at the farthest distance (a",
        "lower bound; ranked above every measured OD50), \\< 25 when AP is below 0.5 already at the nearest",
        "(ranked below every measured OD50); among themselves both rank by the **AP range**, the area under",
        "AP vs distance in metres (defined for every camera; shown for the two ranked conditions). An extrapolated OD50",
        "is neither shown nor ranked by, and no tie is broken by AP at one distance. MTF50 is measured on the camera's",
        "simulated slanted edge (ISO 12233), or the paper's published group where marked, in cycles/mm on",
        "the sensor and in cycles/mrad in object space (× focal length / 1000): only the angular figure",
        "compares cameras whose focal lengths differ. Open [index.html](index.html) for a sortable table;",
        "see [docs/leaderboard.md](../docs/leaderboard.md) for the submission format and rules.", "",
        *([_md(few_footnote()) + ".", ""] if _few(submissions) else []),
        f"{len(submissions)} submission(s)" + (f"; newest {latest}." if latest else "."), "",
    ]  # fmt: skip
    bands = band_figures(submissions, protocols)
    for protocol, subs in _by_protocol(submissions, protocols):
        cols = columns(protocol)
        lines += [f"## {_md(protocol.name)}", "", f"{_md(protocol.description)}.", ""]
        if not subs:
            lines += ["No submissions yet.", ""]
            continue
        lines.append("| " + " | ".join(c.header for c in cols) + " |")
        lines.append("|" + "|".join("---:" if c.kind == "num" else "---" for c in cols) + "|")
        for rank, sub in enumerate(subs, 1):
            cells = row_cells(rank, sub, protocol)
            cells["system"] = ("", f"[{_md(sub['name'])}](submissions/{sub['name']}.json)")
            lines.append("| " + " | ".join(_md(cells[c.key][1]) if c.key != "system" else cells[c.key][1] for c in cols) + " |")
        lines.append("")
        if protocol.name in bands and band_file(protocol):
            text, command = _band_caption(submissions, protocol)  # (band_file: a protocol name safe in a code span)
            lines += [f"![references' AP vs distance, {_md(protocol.name)}]({band_file(protocol)})", "",
                      f"{_md(text)} `{command}`.", ""]
    lines += [
        "## Reproduce the reference submissions", "",
        "The 13 paper cameras with YOLOv5n on each protocol's collection (all conditions):", "",
        "```sh", REPRODUCE, "```", "",
        "## Submit", "",
        "```sh",
        "benchmark submit RUN_OR_SWEEP_FOLDER --name NAME --submitter 'WHO'   # writes leaderboard/submissions/NAME.json",
        "benchmark submit --check leaderboard/submissions/NAME.json            # what the maintainers run",
        "benchmark leaderboard                                                 # re-renders this file and index.html",
        "```", "",
    ]  # fmt: skip
    return "\n".join(lines)


def _asset(name: str) -> str:
    return resources.files("benchmark.leaderboard").joinpath("data", name).read_text(encoding="utf-8")


def _csp_hash(text: str) -> str:
    return "'sha256-" + base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode() + "'"


def render_html(submissions: list[dict], protocols: dict[str, Protocol]) -> str:
    esc = html.escape
    style, script = _asset("leaderboard.css"), _asset("leaderboard.js")
    csp = f"default-src 'none'; style-src {_csp_hash(style)}; script-src {_csp_hash(script)}; base-uri 'none'; form-action 'none'"
    latest = max((s["created_at"] for s in submissions), default=None)
    day, night = _ranked_labels(protocols)
    bands = band_figures(submissions, protocols)
    out = [
        "<!DOCTYPE html>", '<html lang="en">', "<head>", '<meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{esc(csp)}">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        "<title>metricscenes leaderboard</title>", f"<style>{style}</style>", "</head>", "<body>",
        "<h1>metricscenes leaderboard</h1>",
        f"<p>Ranked by the OD50 in {esc(day)} (distance at which COCO AP of the car falls to 0.5), then by the OD50 in "
        f"{esc(night)}. "
        f"± is the bootstrap SD over environments ({esc(_resamples(submissions))}). &gt; 200: AP has not yet fallen "
        "to 0.5 at the farthest distance (a lower bound; ranked above every measured OD50); &lt; 25: below 0.5 already "
        "at the nearest (ranked below every measured OD50); among themselves both rank by the AP range, the area under "
        "AP vs distance in metres (defined for every camera; shown for the two ranked conditions); no tie is broken by AP at one "
        "distance. MTF50 in cycles/mm on the sensor and in cycles/mrad in object space (× focal length / 1000): "
        "only the angular figure compares cameras whose focal lengths differ. Click a column to sort.</p>",
        *([f'<p class="meta">{esc(few_footnote())}.</p>'] if _few(submissions) else []),
        f'<p class="meta">{len(submissions)} submission(s)' + (f"; newest {esc(latest)}" if latest else "") + ".</p>",
    ]  # fmt: skip
    for protocol, subs in _by_protocol(submissions, protocols):
        cols = columns(protocol)
        out += [f'<section id="protocol-{esc(protocol.name)}">', f"<h2>{esc(protocol.name)}</h2>", f"<p>{esc(protocol.description)}.</p>"]
        if not subs:
            out += ['<p class="empty">No submissions yet.</p>', "</section>"]
            continue
        out.append(f'<div class="scroll"><table class="sortable" data-protocol="{esc(protocol.name)}">')
        out.append("<thead><tr>" + "".join(
            f'<th data-key="{c.key}" data-type="{c.kind}" aria-sort="{"ascending" if c.key == "rank" else "none"}">'
            f'<button type="button">{esc(c.header)}</button></th>' for c in cols) + "</tr></thead>")  # fmt: skip
        out.append("<tbody>")
        for rank, sub in enumerate(subs, 1):
            cells = row_cells(rank, sub, protocol)
            tds = []
            for c in cols:
                value, text = cells[c.key]
                body = f'<a href="submissions/{esc(sub["name"])}.json">{esc(text)}</a>' if c.key == "system" else esc(text)
                tds.append(f'<td data-v="{esc(value)}"{_cell_class(c)}>{body}</td>')
            out.append(f'<tr data-name="{esc(sub["name"])}">' + "".join(tds) + "</tr>")
        out += ["</tbody>", "</table></div>"]
        if protocol.name in bands:
            out += ['<figure class="band">', bands[protocol.name].rstrip("\n"),
                    "<figcaption>{} <code>{}</code>.</figcaption>".format(*map(esc, _band_caption(submissions, protocol))),
                    "</figure>"]
        out.append("</section>")
    out += [f"<script>{script}</script>", "</body>", "</html>", ""]
    return "\n".join(out)


WRAPPED_COLUMNS = ("detector", "submitter")
"""Columns whose text may wrap (free text, model names); every other cell stays on one line, so that the
table fits a 1400 px window without scrolling sideways (tests/test_leaderboard_html.py)."""


def _cell_class(column: Column) -> str:
    classes = (["t"] if column.kind == "str" else []) + (["wrap"] if column.key in WRAPPED_COLUMNS else [])
    return f' class="{" ".join(classes)}"' if len(classes) > 1 else (f" class={classes[0]}" if classes else "")


def render_leaderboard(leaderboard_dir: str | Path = "leaderboard") -> tuple[Path, Path]:
    """Validate every submission, then write the references' band figures, ``README.md`` and
    ``index.html`` atomically (a band file no protocol draws any more is removed); returns the
    paths of README.md and index.html."""
    leaderboard_dir = Path(leaderboard_dir)
    protocols = load_protocols(leaderboard_dir)
    submissions = load_submissions(leaderboard_dir, protocols)
    readme, page = render_markdown(submissions, protocols), render_html(submissions, protocols)
    figures = {band_file(protocols[name]): svg for name, svg in band_figures(submissions, protocols).items()
               if band_file(protocols[name])}
    for name, svg in sorted(figures.items()):
        write_atomic(leaderboard_dir / name, svg)
    for stale in sorted(leaderboard_dir.glob("references-*.svg")):
        if stale.name not in figures:
            stale.unlink()
    return write_atomic(leaderboard_dir / "README.md", readme), write_atomic(leaderboard_dir / "index.html", page)
