"""Photon transfer: the figures of an EMVA 1288 report, measured on the camera model.

Flat fields — every pixel the same noise-free signal — go through the camera's own
acquisition (:func:`benchmark.camera.acquisition.acquire`: its readouts, merge and
companding) at a ladder of signal levels, two frames per level with independent temporal
noise. As EMVA 1288 (Release 4.0, 2021, "Standard for characterization of image sensors
and cameras", sections 6.1–6.3) prescribes: the mean of the two frames is the signal, half
the variance of their difference the temporal variance (fixed-pattern noise cancels), the
dark frame's temporal noise σ_d the noise floor, the brightest level's mean the
saturation μ_sat. From these:

* **dynamic range** 20·log10(μ_sat / σ_d), in electrons of the large photodiode;
* **SNR10 (and SNR1) illuminance**: the signal where the measured SNR crosses 10 (1),
  converted to lux at the sensor for a D65 flat field and the camera's reference exposure
  (:func:`electrons_per_lux_s`; green pixels, or clear ones for RCCB/RCCC);
* **HDR transitions**: where the merge hands each pixel to the next readout (half the
  pixels of a level on it), in electrons and lux, with the SNR just after (the "SNR dip"
  of an HDR sensor).

The merged signal is in DN of the HCG readout; dividing by its DN per electron puts every
readout's level in electrons of the large photodiode. A single-readout sensor gives its one
readout's figures. Nothing here reads the figures from the spec: they come out of the
simulated frames (docs/camera.md, "Datasheet figures").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from benchmark.camera import dual_gain as _dual_gain
from benchmark.camera.acquisition import acquire
from benchmark.camera.spec import CameraSpec
from benchmark.camera.spec_exposure import ExposureSpec

PATCH_PX = (32, 64)
"""Rows × columns of one flat-field level (an even number of rows: every CFA site)."""
LEVELS_PER_DECADE = 40
"""Signal levels per factor of 10 (each 6 % above the last): enough to place a transition
within a few per cent."""
LOWEST_LEVEL_E = 0.1
ILLUMINANT = "D65"


@dataclass(frozen=True)
class PhotonTransfer:
    """A photon-transfer measurement.

    Attributes:
        exposure_s: the flat fields' exposure.
        electrons: (levels,) noise-free signal per pixel, electrons of the large photodiode.
        mean_e: (levels,) merged signal above black, electrons (mean of the two frames).
        temporal_var_e2: (levels,) temporal variance, e⁻² (half the variance of the difference).
        readout_fraction: (levels, readouts) fraction of the pixels the merge takes from each readout.
        readout_names: the readouts, in order (``hcg``, ``lcg``, ``spd``; a single-readout sensor: ``hcg``).
        frames: per raw frame name, (mean DN above black, temporal variance DN²) per level.
    """

    exposure_s: float
    electrons: np.ndarray
    mean_e: np.ndarray
    temporal_var_e2: np.ndarray
    readout_fraction: np.ndarray
    readout_names: tuple[str, ...]
    frames: dict[str, tuple[np.ndarray, np.ndarray]]

    @property
    def snr(self) -> np.ndarray:
        """Measured SNR per level (0 where there is no signal)."""
        noise = np.sqrt(self.temporal_var_e2)
        return np.divide(self.mean_e, noise, out=np.zeros_like(self.mean_e), where=noise > 0)


def signal_ladder_e(camera: CameraSpec) -> np.ndarray:
    """0, then :data:`LEVELS_PER_DECADE` levels per decade from :data:`LOWEST_LEVEL_E` to
    1.5 × the top of the camera's range (so the last levels saturate)."""
    top = 1.5 * _dual_gain.merged_saturation_e(camera.sensor)
    count = int(math.ceil(math.log10(top / LOWEST_LEVEL_E) * LEVELS_PER_DECADE)) + 1
    return np.concatenate([[0.0], np.geomspace(LOWEST_LEVEL_E, top, count)])


def photon_transfer(camera: CameraSpec, electrons: np.ndarray | None = None, *, exposure_s: float = 0.016,
                    patch_px: tuple[int, int] = PATCH_PX, seed: int = 0) -> PhotonTransfer:
    """Flat fields at ``electrons`` (default :func:`signal_ladder_e`) per pixel, through the
    camera's acquisition at a fixed ``exposure_s`` (the signal's rate is level / exposure:
    dark current counts as it would), two frames (seeds ``seed``, ``seed + 1``)."""
    levels = signal_ladder_e(camera) if electrons is None else np.asarray(electrons, float)
    rows, cols = patch_px
    rate = np.repeat(levels / exposure_s, rows)[:, None] * np.ones((1, cols))
    fixed = camera.model_copy(update={"exposure": ExposureSpec(mode="fixed", exposure_s=exposure_s)})
    first, second = (acquire(rate, fixed, seed=s) for s in (seed, seed + 1))
    sensor = camera.sensor
    steps = _dual_gain.readouts(sensor)
    per_e = _dual_gain.dn_per_electron(sensor, steps[0])
    black = float(sensor.black_level_dn)

    def by_level(image: np.ndarray) -> np.ndarray:
        return np.asarray(image, np.float64).reshape(levels.size, rows, cols) - black

    def mean_and_var(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a, b = by_level(a), by_level(b)
        return 0.5 * (a.mean(axis=(1, 2)) + b.mean(axis=(1, 2))), 0.5 * (a - b).var(axis=(1, 2))

    mean, var = mean_and_var(first.linear_dn, second.linear_dn)
    frames = {f.name: mean_and_var(f.raw_dn, second.frame(f.name).raw_dn) for f in first.frames}
    if len(steps) > 1:
        choice = _dual_gain.readout_choice({f.name: f.raw_dn for f in first.frames}, sensor).reshape(levels.size, -1)
        fraction = np.stack([(choice == i).mean(axis=1) for i in range(len(steps))], axis=1)
    else:
        fraction = np.ones((levels.size, 1))
    return PhotonTransfer(exposure_s, levels, mean / per_e, var / per_e**2, fraction, tuple(r.name for r in steps),
                          frames)


def electrons_per_lux_s(camera: CameraSpec) -> float:
    """Electrons per lux·s at the sensor of a green pixel (the clear one of an RCCB or RCCC
    sensor) under a flat :data:`ILLUMINANT` irradiance: its responsivity (QE × IR cut ×
    pixel area, :func:`benchmark.camera.sensor.channel_responsivity`) over the illuminant's
    spectrum scaled to 1 lux (683 lm/W × Σ E·ȳ·Δλ over the model's 400–700 nm bands)."""
    from benchmark.camera.calibration import illuminant_spectrum
    from benchmark.camera.sensor import channel_responsivity
    from metricscenes.photometry import radiance_to_xyz

    spectrum = illuminant_spectrum(ILLUMINANT)
    one_lux = spectrum / float(radiance_to_xyz(spectrum)[1])
    return float(channel_responsivity(camera.sensor)[1] @ one_lux)


def _crossing(x: np.ndarray, y: np.ndarray, level: float) -> float | None:
    """First x (log-interpolated) where y rises through ``level``; None where it never does."""
    above = np.nonzero(y >= level)[0]
    if above.size == 0:
        return None
    i = int(above[0])
    if i == 0 or x[i - 1] <= 0:
        return float(x[i])
    t = (level - y[i - 1]) / (y[i] - y[i - 1])
    return float(math.exp(math.log(x[i - 1]) + t * (math.log(x[i]) - math.log(x[i - 1]))))


def datasheet_figures(camera: CameraSpec, ptc: PhotonTransfer | None = None) -> dict:
    """The camera's EMVA-style figures from its photon transfer (JSON-ready, units in the
    keys): dark noise, saturation, dynamic range, SNR10 / SNR1 signal and illuminance, the
    maximum SNR, and the HDR transitions. Exposure: the camera's cap (its SNR reference)."""
    from benchmark.camera.exposure import reference_exposure_s

    exposure_s = reference_exposure_s(camera)
    ptc = ptc or photon_transfer(camera, exposure_s=exposure_s)
    lit = ptc.electrons > 0
    e, snr = ptc.electrons[lit], ptc.snr[lit]
    dark = math.sqrt(ptc.temporal_var_e2[~lit][0])
    saturation = float(ptc.mean_e[-1])
    per_lux = electrons_per_lux_s(camera) * exposure_s

    def lux(electrons: float | None) -> float | None:
        return None if electrons is None else electrons / per_lux

    out = {
        "method": f"photon transfer (EMVA 1288): flat fields through the camera's acquisition, two frames per level, "
                  f"{ptc.electrons.size} levels; lux at the sensor, {ILLUMINANT}, "
                  f"{'clear' if 'C' in camera.sensor.cfa else 'green'} pixels, {exposure_s * 1e3:g} ms",
        "exposure_s": exposure_s,
        "dark_noise_e": round(dark, 4),
        "saturation_e": round(saturation, 1),
        "dynamic_range_db": round(20 * math.log10(saturation / dark), 2) if dark > 0 else None,
        "snr_max_db": round(20 * math.log10(float(snr[e < 0.95 * saturation].max())), 2),
        "electrons_per_lux_s": round(per_lux / exposure_s, 2),
    }
    for level in (10, 1):
        at = _crossing(e, snr, float(level))
        out[f"snr{level}_e"] = None if at is None else round(at, 3)
        out[f"snr{level}_lux"] = None if at is None else float(f"{lux(at):.4g}")
    transitions = []
    for i, name in enumerate(ptc.readout_names[1:], start=1):
        on = ptc.readout_fraction[lit][:, i:].sum(axis=1)
        at = _crossing(e, on, 0.5)
        after = np.nonzero(on >= 0.99)[0]
        transitions.append({
            "to": name, "from": ptc.readout_names[i - 1],
            "electrons": None if at is None else round(at, 1),
            "lux": None if at is None else float(f"{lux(at):.4g}"),
            "snr_db_after": round(20 * math.log10(float(snr[after[0]])), 2) if after.size else None,
        })
    out["transitions"] = transitions
    return out
