"""Acquisition: the sensor's noise-free signal (an electron-rate mosaic, e⁻/s) to a
:class:`RawCapture` — the raw frames as the sensor reads them, their exposures and the
merged linear signal the ISP processes. One function per strategy; :func:`acquire` picks
the camera's:

* :func:`acquire_single` — one exposure (the paper's; every policy but ``hdr``);
* :func:`acquire_two_frames` — ``exposure.mode: hdr``: a long and a short exposure
  ``hdr_ratio`` apart, merged before the ISP (:func:`merge_two_exposures_dn`);
* :func:`acquire_dual_gain` — ``sensor.dcg``: one exposure of an HDR pixel read at several
  gains (and, split, from two photodiodes), merged on the sensor into a linear word and
  companded (:mod:`benchmark.camera.dual_gain`).

An HDR capture says where its reference white lies (``reference_scale``: the factor that
brings the linear signal to units of the white of the camera's reference exposure) and the
merged white in those units (``white``), which the ISP's tone curve reads
(:func:`benchmark.camera.isp.render`); a single exposure has neither. The temporal noise is
deterministic for a seed: the first (or only) frame draws from ``default_rng(seed)``, as a
single capture does; the two-frame HDR's short frame from the first child of
``SeedSequence(seed)`` (an independent stream); the dual-gain readouts from
``default_rng(seed)`` in a fixed order (docs/camera.md, "Acquisition").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmark.camera import dual_gain as _dual_gain
from benchmark.camera import exposure as _exposure
from benchmark.camera import sensor as _sensor
from benchmark.camera.spec import CameraSpec
from benchmark.camera.spec_sensor import SensorSpec

STRATEGIES = ("single", "two_frame_hdr", "dual_gain")
"""The acquisition strategies (:attr:`RawCapture.strategy`), one function each."""


@dataclass(frozen=True)
class RawFrame:
    """One raw frame as the sensor's ADC gives it.

    Attributes:
        name: ``single``, ``long``, ``short`` (two-frame HDR) or a readout of an HDR pixel
            (``hcg``, ``lcg``, ``spd``).
        raw_dn: (rows, cols) uint16 mosaic, black level included.
        exposure_s: its integration time, s.
    """

    name: str
    raw_dn: np.ndarray
    exposure_s: float


@dataclass(frozen=True)
class RawCapture:
    """What one acquisition hands the ISP.

    Attributes:
        strategy: one of :data:`STRATEGIES`.
        frames: the raw frames, in the order they were read.
        exposure_s: the integration time of record, s (the one exposure; two-frame HDR: the long).
        linear_dn: (rows, cols) the merged linear signal, DN on the first frame's scale, black
            level included: what the ISP processes (single: the raw itself, uint16; two-frame
            HDR: float32; dual gain: the companded output decompanded, float32).
        electrons: (rows, cols) float32 noise-free signal electrons of the mosaic at ``exposure_s``.
        output_dn: what the sensor sends where it is not a frame: the companded word (dual gain).
        merged_dn: the sensor's merged linear word before companding (dual gain, uint32).
        reference_scale: HDR only: ``linear_dn``'s units × this = units of the reference
            exposure's white (the tone curve's unit); None: no tone curve.
        white: HDR only: the merged white in those units (the tone curve's w).
    """

    strategy: str
    frames: tuple[RawFrame, ...]
    exposure_s: float
    linear_dn: np.ndarray
    electrons: np.ndarray
    output_dn: np.ndarray | None = None
    merged_dn: np.ndarray | None = None
    reference_scale: float | None = None
    white: float | None = None

    def frame(self, name: str) -> RawFrame:
        """The frame called ``name`` (KeyError if there is none)."""
        for f in self.frames:
            if f.name == name:
                return f
        raise KeyError(f"no frame {name!r} in a {self.strategy} capture ({', '.join(f.name for f in self.frames)})")


def acquisition_strategy(camera: CameraSpec) -> str:
    """The camera's strategy: ``dual_gain`` for an HDR pixel (``sensor.dcg``), ``two_frame_hdr``
    for ``exposure.mode: hdr``, else ``single``."""
    if camera.sensor.dcg is not None:
        return "dual_gain"
    return "two_frame_hdr" if camera.exposure.mode == "hdr" else "single"


def acquire(electron_rate: np.ndarray, camera: CameraSpec, *, seed: int, noise: bool = True) -> RawCapture:
    """The camera's acquisition (:func:`acquisition_strategy`) of a noise-free electron-rate
    mosaic (rows, cols), e⁻/s. ``noise`` False switches every noise source off."""
    strategy = acquisition_strategy(camera)
    if strategy == "dual_gain" and camera.exposure.mode == "hdr":
        raise ValueError(f"camera {camera.name!r}: exposure.mode 'hdr' (two frames) with sensor.dcg (an HDR pixel "
                         "read in one exposure): give one of them")
    opts = _sensor.NoiseOptions() if noise else _sensor.NoiseOptions.off()
    run = {"single": acquire_single, "two_frame_hdr": acquire_two_frames, "dual_gain": acquire_dual_gain}[strategy]
    return run(electron_rate, camera, seed=seed, noise=opts)


def _electrons(electron_rate: np.ndarray, exposure_s: float) -> np.ndarray:
    return np.multiply(electron_rate, np.float32(exposure_s), dtype=np.float32)


def acquire_single(electron_rate: np.ndarray, camera: CameraSpec, *, seed: int,
                   noise: _sensor.NoiseOptions = _sensor.NoiseOptions()) -> RawCapture:
    """One exposure at the camera's policy (:func:`benchmark.camera.exposure.exposure_time_s`),
    one raw: the paper's acquisition."""
    exposure_s = _exposure.exposure_time_s(electron_rate, camera.sensor, camera.exposure)
    raw = _sensor.capture_dn(electron_rate, exposure_s, camera.sensor, np.random.default_rng(seed), noise)
    return RawCapture("single", (RawFrame("single", raw, exposure_s),), exposure_s, raw,
                      _electrons(electron_rate, exposure_s))


# ── two-frame HDR ───────────────────────────────────────────────────────────────────────

SWITCH_FRACTION = 0.95
"""The long exposure is used below this fraction of the raw's saturation: a margin so
that the shot and read noise of a pixel sitting at the clip never pick a clipped value."""


def saturation_dn(sensor: SensorSpec) -> float:
    """Signal DN above the black level at which a raw saturates (the ADC or the well)."""
    return _sensor.saturation_electrons(sensor) * _sensor.signal_volts_per_electron(sensor) / sensor.lsb_v


def merge_two_exposures_dn(raw_long_dn: np.ndarray, raw_short_dn: np.ndarray, ratio: float,
                           sensor: SensorSpec, *, switch_fraction: float = SWITCH_FRACTION) -> np.ndarray:
    """Merged raw (rows, cols) float32 DN on the long exposure's scale, black level included.

    Rule, per pixel: s_long = raw_long − black; if s_long < ``switch_fraction`` ×
    saturation, merged = raw_long, else merged = black + ``ratio`` × (raw_short − black):
    the two-exposure case of the radiance-map merge of Mann & Picard (1995, "On being
    'undigital' with digital cameras", IS&T) and Debevec & Malik (1997, "Recovering high
    dynamic range radiance maps from photographs", SIGGRAPH), with the response known to be
    linear and a hard switch as the weighting.

    Args:
        raw_long_dn, raw_short_dn: uint16 Bayer mosaics of the same scene, DN.
        ratio: t_long / t_short.
    """
    black = np.float32(sensor.black_level_dn)
    signal_long = raw_long_dn.astype(np.float32) - black
    signal_short = (raw_short_dn.astype(np.float32) - black) * np.float32(ratio)
    use_short = signal_long >= np.float32(switch_fraction * saturation_dn(sensor))
    return np.where(use_short, signal_short, signal_long) + black


def acquire_two_frames(electron_rate: np.ndarray, camera: CameraSpec, *, seed: int,
                       noise: _sensor.NoiseOptions = _sensor.NoiseOptions()) -> RawCapture:
    """The ``hdr`` policy: a long and a short raw ``hdr_ratio`` apart
    (:func:`benchmark.camera.exposure.hdr_exposures_s`), merged before the ISP
    (:func:`merge_two_exposures_dn`) on the long frame's scale. The long frame draws its
    temporal noise from ``default_rng(seed)`` (the draws a single capture would make), the
    short one from the first child of ``SeedSequence(seed)``. The reference is the
    ``auto_peak`` exposure: ``reference_scale`` = t_ref / t_long, ``white`` = t_ref / t_short."""
    times = _exposure.hdr_exposures_s(electron_rate, camera.sensor, camera.exposure)
    short_rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])
    raw_long = _sensor.capture_dn(electron_rate, times.long_s, camera.sensor, np.random.default_rng(seed), noise)
    raw_short = _sensor.capture_dn(electron_rate, times.short_s, camera.sensor, short_rng, noise)
    merged = merge_two_exposures_dn(raw_long, raw_short, times.long_s / times.short_s, camera.sensor)
    frames = (RawFrame("long", raw_long, times.long_s), RawFrame("short", raw_short, times.short_s))
    return RawCapture("two_frame_hdr", frames, times.long_s, merged, _electrons(electron_rate, times.long_s),
                      reference_scale=times.reference_s / times.long_s, white=times.reference_s / times.short_s)


# ── an HDR pixel read in one exposure ───────────────────────────────────────────────────

def acquire_dual_gain(electron_rate: np.ndarray, camera: CameraSpec, *, seed: int,
                      noise: _sensor.NoiseOptions = _sensor.NoiseOptions()) -> RawCapture:
    """``sensor.dcg``: one exposure, every readout of the HDR pixel
    (:func:`benchmark.camera.dual_gain.read_out`), merged on the sensor into the linear word
    (:func:`~benchmark.camera.dual_gain.merge_dn`), companded for output
    (:func:`~benchmark.camera.dual_gain.compand`) and decompanded by the host into
    ``linear_dn`` (the ISP's input).

    The exposure: the camera's policy placed on the merged range
    (:func:`benchmark.camera.exposure.exposure_time_s` with ``range_ratio`` =
    :func:`~benchmark.camera.dual_gain.merged_range_ratio`), capped; the reference is the
    policy on the HCG raw alone, as a single-gain camera would expose (``reference_scale`` =
    t_ref / t, ``white`` = the merged white in the reference's units: 1 where the cap does not
    bind, so the image is the reference's with the HDR pixel's noise; more at the cap, where
    the tone curve compresses the highlights the HCG raw would clip)."""
    sensor, policy = camera.sensor, camera.exposure
    ratio = _dual_gain.merged_range_ratio(sensor)
    exposure_s = _exposure.exposure_time_s(electron_rate, sensor, policy, range_ratio=ratio)
    reference_s = _exposure.exposure_time_s(electron_rate, sensor, policy)
    raws = _dual_gain.read_out(electron_rate, exposure_s, sensor, np.random.default_rng(seed), noise)
    word = _dual_gain.merged_word(_dual_gain.merge_dn(raws, sensor), sensor)
    knees = sensor.dcg.companding_knees
    output = _dual_gain.compand(word, knees)
    linear = _dual_gain.decompand(output, knees).astype(np.float32)
    frames = tuple(RawFrame(name, raw, exposure_s) for name, raw in raws.items())
    return RawCapture("dual_gain", frames, exposure_s, linear, _electrons(electron_rate, exposure_s), output_dn=output,
                      merged_dn=word, reference_scale=reference_s / exposure_s, white=ratio * reference_s / exposure_s)
