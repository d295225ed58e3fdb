"""The files runs and sweeps write, as typed records: where their schemas are defined.

One pydantic model per file kind and one read/write pair per file; the writers go through
:func:`metricscenes.files.write_atomic` (a reader never sees half a file) and the readers
raise :class:`ResultsFileError`, one line naming the file, for anything that is not the
record (bad JSON, a missing column, a field of the wrong type):

| file | model | read / write | written by | read by |
|---|---|---|---|---|
| ``results.json`` | :class:`RunResults` | :func:`read_results` / :func:`write_results` | ``experiments.run`` | sweep (cache), report, compare, ``leaderboard.submission``, cli |
| ``od50.json`` | :class:`Od50Cache` (:class:`~benchmark.scoring.bootstrap.Od50Bootstrap`) | :func:`read_od50_cache` / :func:`write_od50_cache` | ``experiments.sweep.run_od50`` | sweep, report, submission |
| ``sweep.csv`` | :class:`SweepRow`, one per row | :func:`read_sweep_table` / :func:`write_sweep_table` | sweep | report, spm, acceptance, cli |
| ``od50.csv`` | :class:`Od50Row`, one per row | :func:`read_od50_table` / :func:`write_od50_table` | sweep | report, spm, acceptance, cli |
| ``sweep.json`` | :class:`SweepRecord` | :func:`read_sweep_record` / :func:`write_sweep_record` | sweep | report, compare |
| ``images.sha256`` | {image file: sha256} | :func:`read_image_hashes` / :func:`write_image_hashes` | ``experiments.run`` | ``run.read_captures`` (``--captures-from``) |

Units, everywhere: AP and AP50 are unitless (COCO AP of the car, 0 to 1; NaN at a distance
whose images hold no car); distances and OD50 are in metres (``_m``); exposures and timings
in seconds (``_s``); MTF50 in cycles per mm on the sensor (``_cy_per_mm``) and, beside it,
in cycles per mrad in object space (``_cy_per_mrad``: × focal length / 1000, what compares
cameras whose focal lengths differ). OD50 may be **censored**: where AP
does not cross 0.5 inside the measured distances the number is an extrapolation (or +inf),
and what is reported is a bound, "> 200 m" or "< 25 m" (:mod:`benchmark.scoring.od50`,
docs/scoring.md). The records keep the number; :meth:`RunResults.od50_censoring`,
``Od50Bootstrap.censored`` and ``Od50Row.censored`` say whether it is a bound.

Bytes. A file holds the fields its writer set, in the order the model declares them (an
optional field left unset stays out of the file), floats as Python's repr, JSON with
``indent=1``: the bytes the dict-based writers wrote before these records, so older results
still hash, cache and compare the same (tests/test_result_files.py reads and rewrites them).
Strict JSON (``od50.json``, ``sweep.json``) holds NaN as null and ±inf as "inf"/"-inf"
(:func:`json_safe`); ``results.json`` holds its floats as ``json.dumps`` writes them (a NaN
AP as ``NaN``). Every model keeps keys it does not know (``extra="allow"``), and the fields
that older files or hand-made runs lack are optional, with the default their readers
always assumed.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from benchmark.record_base import Censored, JsonFloat, Record
from benchmark.scoring.bootstrap import Od50Bootstrap
from benchmark.scoring.od50 import od50_censoring
from metricscenes.files import write_atomic

RESULTS_FORMAT = "metricscenes-results/1"
SWEEP_FORMAT = "metricscenes-sweep/1"
DEFAULT_SCORING_BACKEND = "faster-coco-eval"


class ResultsFileError(ValueError):
    """A result file that is not its record: one line naming the file and what is wrong."""


# ── results.json: one camera × one condition (benchmark.experiments.run) ───────────────────

class DistanceAP(Record):
    """AP of the car at one distance (:func:`benchmark.scoring.ap_by_distance`)."""

    distance_m: float  # camera to car, m
    ap: float  # COCO AP@[.50:.05:.95], unitless; NaN where no image at this distance holds a car
    ap50: float  # AP at IoU 0.5
    n_images: int  # images (environments) at this distance
    miss_rate: float | None = None  # at the working threshold (benchmark.scoring.FOUND_SCORE, FOUND_IOU); absent in older runs
    false_positives_per_image: float | None = None  # car detections at that threshold that do not find the car, per image


class CameraRecord(Record):
    """The camera of a run: its name, headline numbers and the resolved spec."""

    name: str
    pixel_um: float | None = None  # pixel pitch, µm
    f_number: float | None = None
    width_px: int | None = None
    height_px: int | None = None
    focal_length_mm: float | None = None  # absent in results written before angular MTF50 was recorded
    fov_deg: list[float] | None = None  # (horizontal, vertical) field of view
    mtf50_cy_per_mm: float | None = None  # benchmark.measure.mtf.camera_mtf50: measured, else analytic
    mtf50_cy_per_mrad: float | None = None  # the same in object space: × focal length / 1000
    mtf50_source: str | None = None  # measured | analytic | published_group | none
    spec_sha256: str | None = None  # CameraSpec.sha256(): part of the sweep's cache key
    spec: dict[str, Any] | None = None  # CameraSpec.model_dump(mode="json"), kept as read (camera_from_dump checks it)


class DetectorRecord(Record):
    """The detector of a run (``sweep.json`` records name, sha256 and input size only)."""

    name: str
    family: str | None = None
    sha256: str
    input_size: int | str  # pixels, or "native" | "multiscale"; sweep.json writes it as a string
    score_threshold: float | None = None  # detections kept from this score up (0.001: the whole PR curve)
    multi_label: bool | None = None  # every class above threshold per box (YOLOv5 val.py)
    class_map: list[str] | None = None  # a COCO name or "-" per model class (docs/detection.md); absent for COCO's 80


class CollectionRecord(Record):
    """The collection a run or sweep read."""

    name: str | None = None
    protocol: str | None = None  # the leaderboard protocol (results.json only)
    manifest_sha256: str  # what a run is comparable on (compare, sweep cache, submissions)
    path: str | None = None


class CameraGeometry(Record):
    """Where a camera sees a window of the collection's field (registry cameras: absent)."""

    hfov_deg: float
    vfov_deg: float
    window_tan: list[float]  # (x0, y0, x1, y1) in tangent coordinates
    collection_fov_deg: list[float]  # (horizontal, vertical) of the collection's field


class Subset(Record):
    """The scenes of a quick try (``--environments``/``--distances``): never a full run."""

    environments: list[int]
    distances_m: list[float]


class RunResults(Record):
    """``results.json`` of one run (:func:`benchmark.experiments.run.run_camera`).

    ``od50_m`` is the OD50 of the full set in m, rounded to mm, None where it is infinite; it
    is the extrapolated number where censored (:meth:`od50_censoring`). The sweep's cache key
    is camera ``spec_sha256``, ``condition``, detector ``sha256`` and ``input_size``,
    collection ``manifest_sha256``, ``seed``, and ``camera_geometry``, ``subset`` and
    detector ``class_map`` where present (:func:`benchmark.experiments.keys.results_key`).
    """

    format: str | None = None  # RESULTS_FORMAT
    package_version: str | None = None
    camera: CameraRecord
    condition: str
    detector: DetectorRecord | None = None
    collection: CollectionRecord
    seed: int = 0  # sensor-noise seed
    scoring_backend: str = DEFAULT_SCORING_BACKEND
    per_distance: list[DistanceAP] = []  # sorted by distance
    od50_m: float | None = None
    exposure_s: dict[str, float] = {}  # per scene id; the long frames of an hdr camera
    detections_file: str = "detections.json"
    detections_sha256: str | None = None  # of detections_file's bytes
    timing_s: dict[str, float] = {}  # wall-clock per stage, summed over scenes (not part of any comparison)
    camera_geometry: CameraGeometry | None = None
    subset: Subset | None = None
    exposure_short_s: dict[str, float] | None = None  # hdr only: the short frames per scene id
    captures_from: str | None = None  # the run folder whose camera images were detected (none simulated)
    composite: str | None = None  # how plate and inset were composited (benchmark.experiments.run.COMPOSITE); None before v0.1.0a5
    condition_weights: dict[str, dict] | None = None  # a targeted condition: per scene, target and weights (metricscenes.targets)
    condition_spec: dict | None = None  # a read-time condition: its definition (not in the manifest's hash; in the cache key)
    car_classes: list[str] | None = None  # COCO classes scored as the car (benchmark.scoring.ap.CAR_CLASSES); None: ["car"]
    numerics: dict | None = None  # versions, ISA class and kernels that decided the bytes (metricscenes.numeric_pins)

    def ap_curve(self) -> tuple[list[float], list[float]]:
        """(distances in m, AP) of ``per_distance``: the points OD50 is read from."""
        return [r.distance_m for r in self.per_distance], [r.ap for r in self.per_distance]

    def od50_censoring(self) -> tuple[str, float | None]:
        """(censored, bound_m) of this run's AP curve (:func:`benchmark.scoring.od50.od50_censoring`)."""
        return od50_censoring(*self.ap_curve())


def read_results(path: str | Path) -> RunResults:
    """The :class:`RunResults` of a ``results.json`` (OSError if it cannot be read)."""
    return _read_json(path, RunResults)


def write_results(path: str | Path, results: RunResults) -> Path:
    """Write ``results.json`` atomically: the fields set, one-space indent (as run.py always wrote it)."""
    return write_atomic(path, json.dumps(_fields_set(results), indent=1))


# ── images.sha256: the sha256 of each camera image a run saved ────────────────────────────

IMAGE_HASHES_FILE = "images.sha256"


def write_image_hashes(path: str | Path, hashes: dict[str, str]) -> Path:
    """Write ``images.sha256`` atomically: one ``<sha256>  images/<file>`` line per image, sorted
    by file name (the format ``sha256sum -c images.sha256`` checks in the run folder)."""
    return write_atomic(path, "".join(f"{digest}  images/{name}\n" for name, digest in sorted(hashes.items())))


def read_image_hashes(path: str | Path) -> dict[str, str]:
    """{image file name: sha256} of an ``images.sha256`` (OSError if it cannot be read)."""
    path = Path(path)
    hashes = {}
    for number, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
        digest, _, name = line.partition("  images/")
        if len(digest) != 64 or not all(c in "0123456789abcdef" for c in digest) or not name or "/" in name:
            raise ResultsFileError(f"{path}: line {number} is not '<sha256>  images/<file>'")
        hashes[name] = digest
    return hashes


# ── od50.json: a run's bootstrap OD50, cached next to its detections ─────────────────────

@dataclass(frozen=True)
class RunFolder:
    """A run folder and its parsed ``results.json`` (what compare and submit read)."""

    folder: Path
    results: RunResults

    @property
    def camera(self) -> str:
        return self.results.camera.name

    @property
    def condition(self) -> str:
        return self.results.condition


class Od50CacheKey(Record):
    """What makes a cached bootstrap reusable: the same detections, resamples and seed."""

    detections_sha256: str | None
    n_resamples: int
    seed: int


class Od50Cache(Record):
    """``od50.json``: the bootstrap and the key it was computed for."""

    key: Od50CacheKey
    od50: Od50Bootstrap


def read_od50_cache(path: str | Path) -> Od50Cache:
    """The :class:`Od50Cache` of an ``od50.json`` (OSError if it cannot be read)."""
    return _read_json(path, Od50Cache)


def write_od50_cache(path: str | Path, cache: Od50Cache) -> Path:
    """Write ``od50.json`` atomically, strict JSON (NaN as null, inf as "inf"), one-space indent."""
    return write_atomic(path, json.dumps(json_safe(_fields_set(cache)), indent=1))


# ── sweep.csv, od50.csv and sweep.json (benchmark.experiments.sweep) ──────────────────────

class SweepRow(Record):
    """One camera × condition × distance of a sweep: a row of ``sweep.csv`` and of sweep.json's ``table``."""

    camera: str
    pixel_um: float  # µm
    f_number: float
    mtf50_cy_per_mm: JsonFloat  # cycles/mm on the sensor; NaN where no source gave one
    mtf50_source: str  # measured | analytic | published_group | none
    condition: str
    distance_m: float
    ap: JsonFloat
    ap50: JsonFloat
    n_images: int
    focal_length_mm: float | None = None  # absent in sweeps written before angular MTF50 was recorded
    mtf50_cy_per_mrad: JsonFloat | None = None  # MTF50 in object space: mtf50_cy_per_mm × focal_length_mm / 1000


class Od50Row(Record):
    """One camera × condition of a sweep: a row of ``od50.csv`` and of sweep.json's ``od50``."""

    camera: str
    pixel_um: float
    f_number: float
    mtf50_cy_per_mm: JsonFloat
    mtf50_source: str
    condition: str
    od50_m: JsonFloat  # m; see Od50Bootstrap (a bound where censored)
    sd_m: JsonFloat
    ci95_lo_m: JsonFloat
    ci95_hi_m: JsonFloat
    n_resamples: int
    n_environments: int
    n_infinite: int
    focal_length_mm: float | None = None  # as SweepRow's
    mtf50_cy_per_mrad: JsonFloat | None = None
    censored: Censored | None = None  # absent in sweeps written before censoring was recorded
    ap_range_m: JsonFloat | None = None  # area under AP vs distance, m (Od50Bootstrap); absent in older sweeps
    ap_range_sd_m: JsonFloat | None = None
    ap_range_ci95_lo_m: JsonFloat | None = None
    ap_range_ci95_hi_m: JsonFloat | None = None


TABLE_COLUMNS = list(SweepRow.model_fields)
OD50_COLUMNS = list(Od50Row.model_fields)


class SweepRun(Record):
    """Where one camera × condition's run folder is, relative to the sweep folder."""

    camera: str
    condition: str
    path: str  # runs/<camera>-<condition>[+<policy>][+subset-<hash>]
    reused: bool  # taken from the cache, not computed by this sweep


class SweepExposure(Record):
    """The ``--exposure`` policy that replaced every camera's own."""

    policy: str
    tag: str
    spec: dict[str, Any]  # ExposureSpec.model_dump(mode="json")


class SweepRecord(Record):
    """``sweep.json``: what a sweep ran on, its runs and both tables."""

    format: str  # SWEEP_FORMAT
    collection: CollectionRecord
    detector: DetectorRecord
    seed: int
    n_resamples: int
    mtf_source: str
    scoring_backend: str
    cameras: list[str]
    conditions: list[str]
    runs: list[SweepRun]
    table: list[SweepRow]
    od50: list[Od50Row]
    subset: Subset | None = None
    exposure: SweepExposure | None = None


def read_sweep_record(path: str | Path) -> SweepRecord:
    """The :class:`SweepRecord` of a ``sweep.json`` (OSError if it cannot be read)."""
    return _read_json(path, SweepRecord)


def write_sweep_record(path: str | Path, record: SweepRecord) -> Path:
    """Write ``sweep.json`` atomically, strict JSON, one-space indent."""
    return write_atomic(path, json.dumps(json_safe(_fields_set(record)), indent=1))


def write_sweep_table(path: str | Path, rows: list[SweepRow]):
    """Write ``sweep.csv`` atomically (columns :data:`TABLE_COLUMNS`); returns the table as a DataFrame."""
    return _write_table(path, rows, TABLE_COLUMNS)


def read_sweep_table(path: str | Path):
    """``sweep.csv`` as a DataFrame; a missing column is a :class:`ResultsFileError`."""
    return _read_table(path, SweepRow)


def write_od50_table(path: str | Path, rows: list[Od50Row]):
    """Write ``od50.csv`` atomically (columns :data:`OD50_COLUMNS`); returns the table as a DataFrame."""
    return _write_table(path, rows, OD50_COLUMNS)


def read_od50_table(path: str | Path):
    """``od50.csv`` as a DataFrame (``censored`` may be absent: older sweeps); a missing column is a :class:`ResultsFileError`."""
    return _read_table(path, Od50Row)


# ── helpers ──────────────────────────────────────────────────────────────────────────────

def json_safe(value):
    """Strict JSON: NaN becomes None, ±inf the strings "inf"/"-inf" (``float()`` reads them back)."""
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    if isinstance(value, (np.floating, float)):
        if math.isnan(value):
            return None
        return float(value) if math.isfinite(value) else ("inf" if value > 0 else "-inf")
    if isinstance(value, np.integer):
        return int(value)
    return value


def _fields_set(record: Record) -> dict:
    # Only what the writer set: an optional field it left out (camera_geometry of a registry
    # camera, subset of a full run) stays out of the file, as it always did.
    return record.model_dump(exclude_unset=True)


def _read_json(path: str | Path, model: type[Record]):
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:  # JSONDecodeError is a ValueError
        raise ResultsFileError(f"{path}: not valid JSON ({str(exc).splitlines()[0]})") from None
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise ResultsFileError(f"{path}: not a {path.name} file ({one_line(exc)})") from None


def one_line(exc: ValidationError, shown: int = 3) -> str:
    """A pydantic error as one line: the first ``shown`` problems as ``where: what``, then a count."""
    problems = [f"{'.'.join(map(str, e['loc'])) or 'top level'}: {e['msg']}" for e in exc.errors()]
    more = f" and {len(problems) - shown} more" if len(problems) > shown else ""
    return "; ".join(problems[:shown]) + more


def _write_table(path: str | Path, rows: list[Record], columns: list[str]):
    import pandas as pd

    table = pd.DataFrame([row.model_dump() for row in rows], columns=columns)
    write_atomic(path, table.to_csv(index=False))
    return table


def _read_table(path: str | Path, model: type[Record]):
    import pandas as pd

    path = Path(path)
    try:
        table = pd.read_csv(path)
    except (ValueError, UnicodeDecodeError) as exc:  # an empty or garbled file (pandas' errors are ValueErrors)
        raise ResultsFileError(f"{path}: not a {path.name} table ({str(exc).splitlines()[0]})") from None
    required = [name for name, field in model.model_fields.items() if field.is_required()]
    missing = [name for name in required if name not in table.columns]
    if missing:
        raise ResultsFileError(f"{path}: not a {path.name} table (missing column(s) {', '.join(missing)})")
    return table
