"""Exposure policies (ISETCam ``autoExposure``; the paper's choice is ``auto_peak``).

ISETCam simulates a noise-free 1 s exposure and scales: t = level × swing / V, where V
is the peak (or mean) signal voltage inside the central region. The paper: level 0.90,
central region, t ≤ 16 ms (60 frames/s). Voltages here are signal volts at the ADC
(conversion gain × analog gain), without the black-level offset.
"""

from __future__ import annotations

import numpy as np

from benchmark.cameras.spec import ExposureSpec, SensorSpec
from benchmark.sensor import signal_volts_per_electron


def central_region(shape: tuple[int, int], fraction: float) -> tuple[slice, slice]:
    """Slices of the centred rectangle covering ``fraction`` of each side."""
    rows, cols = shape
    h = max(1, int(round(rows * fraction)))
    w = max(1, int(round(cols * fraction)))
    r0, c0 = (rows - h) // 2, (cols - w) // 2
    return slice(r0, r0 + h), slice(c0, c0 + w)


def exposure_time_s(electron_rate: np.ndarray, sensor: SensorSpec, policy: ExposureSpec) -> float:
    """Integration time, s, for a noise-free electron-rate mosaic (rows, cols), e⁻/s.

    ``auto_peak``: peak signal voltage in the central region at ``level`` × swing, the
    peak read as the ``peak_percentile`` of the region (100: the strict maximum);
    ``mean_level``: mean signal voltage there at ``level`` × swing; both capped at
    ``max_exposure_s`` (a black region gets the cap). ``fixed``: ``exposure_s``.
    """
    if policy.mode == "fixed":
        return float(policy.exposure_s)
    region = electron_rate[central_region(electron_rate.shape, policy.region_fraction)]
    if policy.mode == "auto_peak":
        rate = float(np.max(region) if policy.peak_percentile >= 100.0 else np.percentile(region, policy.peak_percentile))
    else:
        rate = float(np.mean(region))
    volts_per_s = rate * signal_volts_per_electron(sensor)
    if not np.isfinite(volts_per_s) or volts_per_s <= 0:
        return float(policy.max_exposure_s)
    return float(min(policy.level * sensor.voltage_swing_v / volts_per_s, policy.max_exposure_s))
