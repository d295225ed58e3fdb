"""The rendered leaderboard page in headless Chromium: no console errors (CSP included), and
sorting by a column (``#sort=key`` / ``#sort=-key``, what a header click sets) reorders rows."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from benchmark.leaderboard import build_submission, find_runs, load_protocols, render_leaderboard, write_submission
from synthetic_leaderboard import write_synthetic_run

REPO = Path(__file__).resolve().parents[1]
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--enable-logging=stderr", "--v=0", "--virtual-time-budget=2000",
         "--dump-dom"]  # fmt: skip
# camera, day half range (m): OD50 order cam03 > cam12 > cam01; pixel order cam12 (1.4) < cam03 (2.8) < cam01 (4.2)
SYSTEMS = (("cam03", 150.0), ("cam12", 100.0), ("cam01", 55.0))

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (Debian: apt-get install -y chromium)")


def _browse(url: str, profile: Path, *flags: str) -> tuple[str, list[str]]:
    """(DOM after scripts ran, console messages) of ``url`` in headless Chromium."""
    profile.mkdir(parents=True, exist_ok=True)
    proc = subprocess.run([CHROMIUM, *FLAGS, *flags, f"--user-data-dir={profile}", url], capture_output=True, text=True,
                          timeout=120)
    console = [line for line in proc.stderr.splitlines() if ":CONSOLE" in line]
    return proc.stdout, console


@pytest.fixture(scope="module")
def chromium_works(tmp_path_factory):
    """A page with a console error: Chromium must start and the harness must see the error."""
    tmp = tmp_path_factory.mktemp("probe")
    page = tmp / "probe.html"
    page.write_text('<!DOCTYPE html><html><body><p id="p">x</p><script>document.getElementById("p").textContent = "ran"; '
                    "console.error('probe-error'); undefinedFunction();</script></body></html>")  # fmt: skip
    dom, console = _browse(page.as_uri(), tmp / "profile")
    if ">ran<" not in dom:
        pytest.skip(f"chromium could not render a page here (stdout {dom[:80]!r})")
    assert any("probe-error" in line for line in console) and any("undefinedFunction" in line for line in console), console
    return True


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    from benchmark.camera import load_camera
    from metricscenes.manifest import load_manifest

    root = tmp_path_factory.mktemp("html")
    manifest = load_manifest(REPO / "manifests" / "smoke.yaml")
    lb = root / "leaderboard"
    (lb / "submissions").mkdir(parents=True)
    (lb / "protocols.yaml").write_text(
        "protocols:\n  smoke:\n    description: smoke\n    manifests_sha256: [" + manifest.sha256() + "]\n"
        "    distances_m: [25, 50, 75, 100, 150, 200]\n    conditions: [day, night]\n    required_conditions: [day]\n"
        "    references: sys-*\n"  # the band is drawn: inline SVG under the page's CSP
    )  # fmt: skip
    protocols = load_protocols(lb)
    for i, (cam, half) in enumerate(SYSTEMS):
        conditions = ("day", "night") if cam != "cam12" else ("day",)  # cam12: no night run
        runs = []
        for cond in conditions:
            folder = root / "runs" / f"{cam}-{cond}"
            write_synthetic_run(folder, load_camera(cam), cond, manifest=manifest, seed=i, half_range_m=half if cond == "day" else 40.0 + 10 * i)
            runs += find_runs(folder)
        sub = build_submission(runs, name=f"sys-{cam}", submitter=f"team <{i}>", created_at=f"2025-0{i + 1}-01T00:00:00Z",
                               n_resamples=10, measure_mtf=False, protocols=protocols)  # fmt: skip
        write_submission(sub, lb)
    _, html = render_leaderboard(lb)
    return html


def _order(dom: str) -> list[str]:
    return re.findall(r'<tr data-name="([^"]+)"', dom)


def test_page_loads_without_console_errors(chromium_works, page, tmp_path):
    dom, console = _browse(page.as_uri(), tmp_path / "profile")
    assert console == []  # no errors, no CSP violations, nothing logged
    assert 'data-sorted="rank"' in dom  # the script ran under the page's CSP
    assert '<figure class="band">' in dom and dom.count("<polygon") == 2  # the references' band: day and night
    assert _order(dom) == ["sys-cam03", "sys-cam12", "sys-cam01"]


@pytest.mark.parametrize(
    ("fragment", "expected"),
    [
        ("sort=pixel_um", ["sys-cam12", "sys-cam03", "sys-cam01"]),
        ("sort=-pixel_um", ["sys-cam01", "sys-cam03", "sys-cam12"]),
        ("sort=-system", ["sys-cam12", "sys-cam03", "sys-cam01"]),
        ("sort=night_od50", ["sys-cam03", "sys-cam01", "sys-cam12"]),  # no night value: last either way
        ("sort=-night_od50", ["sys-cam01", "sys-cam03", "sys-cam12"]),
    ],
)
def test_sorting_by_column(chromium_works, page, tmp_path, fragment, expected):
    import json

    subs = {p.stem: json.loads(p.read_text()) for p in (page.parent / "submissions").glob("*.json")}
    if fragment.endswith("night_od50"):  # the synthetic night OD50s are set by half ranges 40 and 60 m: cam01 (60) > cam03 (40)
        assert subs["sys-cam01"]["conditions"]["night"]["od50_m"] > subs["sys-cam03"]["conditions"]["night"]["od50_m"]
    dom, console = _browse(f"{page.as_uri()}#{fragment}", tmp_path / "profile")
    assert console == []
    assert _order(dom) == expected
    key = fragment.removeprefix("sort=").lstrip("-")
    direction = "descending" if fragment.startswith("sort=-") else "ascending"
    assert re.search(rf'<th data-key="{key}" data-type="\w+" aria-sort="{direction}">', dom)


# Writes the page's widths into the DOM once laid out (run on a copy without the CSP, which allows the page's own script only).
MEASURE = ("<script>window.addEventListener('load', () => { const d = document.documentElement; "
           "const boxes = [...document.querySelectorAll('.scroll')].map(e => [e.scrollWidth, e.clientWidth]); "
           "const p = document.createElement('pre'); p.id = 'widths'; "
           "p.textContent = JSON.stringify({page: [d.scrollWidth, d.clientWidth], tables: boxes}); "
           "document.body.appendChild(p); });</script>")


def test_committed_table_fits_1400_px_without_scrolling_sideways(chromium_works, tmp_path):
    """The committed leaderboard (18 columns: four conditions' OD50, day and night AP range, MTF50
    in both units, focal length, field of view) fits a 1400 px wide window: neither the page nor a
    table scrolls sideways."""
    import json

    text = (REPO / "leaderboard" / "index.html").read_text(encoding="utf-8")
    text = re.sub(r'<meta http-equiv="Content-Security-Policy"[^>]*>', "", text).replace("</body>", MEASURE + "</body>")
    copy = tmp_path / "index.html"
    copy.write_text(text, encoding="utf-8")
    dom, _ = _browse(copy.as_uri(), tmp_path / "profile", "--window-size=1400,900")
    found = re.search(r'<pre id="widths">([^<]*)</pre>', dom)
    assert found, dom[-500:]
    widths = json.loads(found.group(1))
    assert widths["page"][0] <= widths["page"][1], widths
    assert widths["tables"] and all(scroll <= client for scroll, client in widths["tables"]), widths
    assert "MTF50 (cy/mrad)" in text and "Focal (mm)" in text and "FOV (°)" in text and "0.1–1 lux image plane, sky raised AP range (m)" in text
    assert text.count('<figure class="band">') == 3  # the references' band under each protocol's table fits too
