"""Exposure policies (ISETCam ``autoExposure``; the paper's choice is ``auto_peak``).

ISETCam simulates a noise-free 1 s exposure and scales: t = level × swing / V, where V
is the peak (or mean) signal voltage inside the central region. The paper: level 0.90,
central region, t ≤ 16 ms (60 frames/s). Voltages here are signal volts at the ADC
(conversion gain × analog gain), without the black-level offset.

Besides the reference (``auto_peak``) a run may choose ``mean_level``, ``percentile``,
``hdr`` (two exposures, :func:`benchmark.camera.acquisition.acquire_two_frames`) or
``fixed``; :func:`parse_exposure` reads the compact syntax of ``benchmark run/sweep
--exposure`` (docs/camera.md, "Acquisition policies") and :func:`check_exposure_override`
refuses a policy that cannot replace a camera's own.
"""

from __future__ import annotations

import hashlib
import re
from typing import NamedTuple

import numpy as np
from pydantic import ValidationError

from benchmark.camera.spec import CameraSpec
from benchmark.camera.spec_exposure import ExposureSpec
from benchmark.camera.spec_sensor import SensorSpec
from benchmark.camera.sensor import signal_volts_per_electron

EXPOSURE_SYNTAX = ("auto_peak | mean_level | percentile:P | hdr[:RATIO] | fixed:SECONDS, "
                   "each but fixed with an optional @LEVEL")


def central_region(shape: tuple[int, int], fraction: float) -> tuple[slice, slice]:
    """Slices of the centred rectangle covering ``fraction`` of each side."""
    rows, cols = shape
    h = max(1, int(round(rows * fraction)))
    w = max(1, int(round(cols * fraction)))
    r0, c0 = (rows - h) // 2, (cols - w) // 2
    return slice(r0, r0 + h), slice(c0, c0 + w)


def exposure_time_s(electron_rate: np.ndarray, sensor: SensorSpec, policy: ExposureSpec, *,
                    range_ratio: float = 1.0) -> float:
    """Integration time, s, for a noise-free electron-rate mosaic (rows, cols), e⁻/s.

    ``auto_peak``: peak signal voltage in the central region at ``level`` × swing, the
    peak read as the ``peak_percentile`` of the region (100: the strict maximum);
    ``percentile``: the ``percentile``-th percentile of the region at ``level`` × swing;
    ``mean_level``: mean signal voltage there at ``level`` × swing; all capped at
    ``max_exposure_s`` (a black region gets the cap). ``fixed``: ``exposure_s``.
    ``hdr``: the long exposure of :func:`hdr_exposures_s`.

    ``range_ratio``: a sensor whose merged signal holds this many times its (first) raw's
    range, an HDR pixel (:func:`benchmark.camera.dual_gain.merged_range_ratio`): every policy
    but ``fixed`` places its statistic at ``level`` of that range, i.e. exposes
    ``range_ratio`` × longer, up to the cap.
    """
    if policy.mode == "fixed":
        return float(policy.exposure_s)
    if policy.mode == "hdr":
        return hdr_exposures_s(electron_rate, sensor, policy).long_s
    region = electron_rate[central_region(electron_rate.shape, policy.region_fraction)]
    if policy.mode == "auto_peak":
        rate = float(np.max(region) if policy.peak_percentile >= 100.0 else np.percentile(region, policy.peak_percentile))
    elif policy.mode == "percentile":
        rate = float(np.max(region) if policy.percentile >= 100.0 else np.percentile(region, policy.percentile))
    else:
        rate = float(np.mean(region))
    volts_per_s = rate * signal_volts_per_electron(sensor)
    if not np.isfinite(volts_per_s) or volts_per_s <= 0:
        return float(policy.max_exposure_s)
    exposure_s = policy.level * sensor.voltage_swing_v / volts_per_s
    if range_ratio != 1.0:
        exposure_s *= range_ratio
    return float(min(exposure_s, policy.max_exposure_s))


class HDRExposures(NamedTuple):
    """The two integration times of an ``hdr`` capture and the reference they come from, s."""

    long_s: float
    short_s: float
    reference_s: float


def hdr_exposures_s(electron_rate: np.ndarray, sensor: SensorSpec, policy: ExposureSpec) -> HDRExposures:
    """Long and short exposure, s, of the two-frame HDR policy (fixed ratio ``hdr_ratio``).

    t_ref is the reference ``auto_peak`` exposure (same ``level``, ``peak_percentile``,
    region and cap); long = min(``hdr_ratio`` × t_ref, ``max_exposure_s``), short =
    long / ``hdr_ratio``. So long ≥ t_ref (shadows get at least the reference's light)
    and short ≤ t_ref (highlights clip no more than in the reference); in daylight the
    short frame *is* the reference, at the cap (night) the long one is.
    """
    reference_s = exposure_time_s(electron_rate, sensor, policy.model_copy(update={"mode": "auto_peak"}))
    long_s = float(min(policy.hdr_ratio * reference_s, policy.max_exposure_s))
    return HDRExposures(long_s, long_s / policy.hdr_ratio, reference_s)


# ── the compact syntax of --exposure ─────────────────────────────────────────────

_SYNTAX = re.compile(r"(?P<mode>[a-z_]+)(?::(?P<arg>[^@]*))?(?:@(?P<level>.*))?")
_ARG_FIELD = {"percentile": "percentile", "hdr": "hdr_ratio", "fixed": "exposure_s"}


def parse_exposure(text: str) -> ExposureSpec:
    """``auto_peak``, ``mean_level``, ``percentile:95``, ``hdr:16``, ``fixed:0.004``, with
    ``@LEVEL`` (e.g. ``percentile:50@0.3``) for all but ``fixed`` → :class:`ExposureSpec`.

    The other fields keep their defaults (central half of the frame, 16 ms cap, peak
    percentile 99.9): the result replaces a camera's whole ``exposure`` block.

    Raises:
        ValueError: one line naming the text, what is wrong and the syntax.
    """
    raw = str(text).strip()
    match = _SYNTAX.fullmatch(raw.lower())

    def bad(why: str) -> ValueError:
        return ValueError(f"--exposure {raw!r}: {why}; expected {EXPOSURE_SYNTAX}")

    if match is None:
        raise bad("not understood")
    mode, arg, level = match["mode"], match["arg"], match["level"]
    modes = ExposureSpec.model_fields["mode"].annotation.__args__
    if mode not in modes:
        raise bad(f"unknown policy {mode!r}")
    fields: dict[str, object] = {"mode": mode}
    if arg is not None:
        if mode not in _ARG_FIELD:
            raise bad(f"{mode} takes no ':' parameter")
        fields[_ARG_FIELD[mode]] = _number(arg, bad)
    elif mode in ("percentile", "fixed"):
        raise bad(f"{mode} needs its parameter ({mode}:{'P' if mode == 'percentile' else 'SECONDS'})")
    if level is not None:
        if mode == "fixed":
            raise bad("fixed takes no @LEVEL")
        fields["level"] = _number(level, bad)
    try:
        return ExposureSpec(**fields)
    except ValidationError as exc:
        err = exc.errors()[0]
        where = ".".join(str(p) for p in err["loc"])
        raise bad(f"{where + ': ' if where else ''}{err['msg']}".replace("Value error, ", "")) from None


def _number(text: str, bad) -> float:
    try:
        value = float(text)
    except ValueError:
        raise bad(f"{text!r} is not a number") from None
    if not np.isfinite(value):
        raise bad(f"{text!r} is not a finite number")
    return value


def format_exposure(policy: ExposureSpec) -> str | None:
    """The compact syntax of ``policy`` (``hdr:16``, ``percentile:95@0.5``), or None when
    the policy sets fields the syntax cannot say (region, cap, peak percentile)."""
    text = policy.mode
    field = _ARG_FIELD.get(policy.mode)
    if field is not None:
        text += f":{_short(getattr(policy, field))}"
    if policy.mode != "fixed" and policy.level != ExposureSpec.model_fields["level"].default:
        text += f"@{_short(policy.level)}"
    try:
        return text if parse_exposure(text) == policy else None
    except ValueError:  # a spec built without validation (model_copy)
        return None


def _short(value: float) -> str:
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def exposure_tag(policy: ExposureSpec) -> str:
    """A file-name-safe, one-to-one label of ``policy`` for run folders: ``hdr-16``,
    ``percentile-95-level0.5``; ``<mode>-<sha256[:8]>`` for policies the syntax cannot say."""
    text = format_exposure(policy)
    if text is None:
        digest = hashlib.sha256(policy.model_dump_json().encode("utf-8")).hexdigest()[:8]
        return f"{policy.mode}-{digest}"
    return text.replace(":", "-").replace("@", "-level")


def check_exposure_override(camera, policy: ExposureSpec | None) -> None:
    """One-line ValueError if ``policy`` (an ``--exposure``) cannot replace ``camera``'s own:
    the two-frame ``hdr`` policy on an HDR pixel (``sensor.dcg``), which merges its own
    readouts in one exposure (two frames of it are not modelled). The CLI calls it where it
    applies ``--exposure``, before anything runs: the capture refuses the pair too
    (:func:`benchmark.camera.acquisition.acquire`), but only once a run has begun."""
    if policy is None or policy.mode != "hdr" or camera.sensor.dcg is None:
        return
    raise ValueError(f"camera {camera.name!r}: --exposure {format_exposure(policy) or 'hdr'} takes two frames, but "
                     "its sensor is an HDR pixel (sensor.dcg) that already merges its own readouts in one exposure: "
                     "use the camera's own exposure policy (no --exposure) or a one-frame one (auto_peak, "
                     "mean_level, percentile:P, fixed:SECONDS)")


def with_exposure(camera, policy: ExposureSpec | None):
    """``camera`` with its exposure block replaced by ``policy`` (None: unchanged). The new
    spec, hence its sha256 and results.json's ``camera.spec``, records the policy. Not
    validated (a model copy): :func:`check_exposure_override` refuses what does not apply."""
    if policy is None:
        return camera
    return camera.model_copy(update={"exposure": policy})


def reference_exposure_s(camera: CameraSpec) -> float:
    """The exposure of the SNR reference: ``exposure_s`` for a ``fixed`` policy, else the
    cap ``max_exposure_s`` (the longest any other policy may take)."""
    e = camera.exposure
    return float(e.exposure_s if e.mode == "fixed" else e.max_exposure_s)
