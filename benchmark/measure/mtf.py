"""MTF50 by the ISO 12233 e-SFR (slanted edge) method, and its analytic oracle.

e-SFR (Burns, "Slanted-edge MTF for digital camera and scanner analysis", PICS 2000;
ISO 12233:2017 Annex D; ISETCam ``ISO12233.m``): per-row derivative and centroid, a
linear fit of the edge (two passes, the second with a Hamming window around the
first fit), every pixel projected on the edge normal into a 4× oversampled
edge-spread function, its central-difference derivative, a Hamming window, |FFT|
normalised at DC. The central difference and the 1/4-pixel bins are corrected
(divided by their sinc responses, as ISO 12233:2017's derivative correction).
Frequencies are cycles/mm on the sensor along the edge normal.

The camera measurement renders :func:`benchmark.measure.targets.slanted_edge_scene` through the
same optics, sensor, acquisition (:func:`benchmark.camera.acquisition.acquire`, noise off:
an HDR pixel's merge and companding included) and ISP (:func:`benchmark.camera.isp.white_balanced_rgb`:
white balance and demosaic) as :func:`benchmark.camera.pipeline.simulate`, and analyses the
luminance 0.3 R + 0.6 G + 0.1 B (ISETCam; the clear channel of an RCCB or RCCC sensor).

``measure_mtf50(camera, esfr="isetcam")`` measures as ISETCam did for the paper's MTF50
groups (ISET/isetauto ``papers/EI2023/s_eiSensorFnumber.m``: ``ieISO12233(ip, sensor)``
with the default ``ip``): :func:`esf_mtf_isetcam` ports ISETCam's ``ISO12233v1`` e-SFR
and :func:`mtf50_isetcam` its MTF50 rule, on ISETCam's 21° slanted bar. With
``isp_preset("iset-parity")`` (bilinear demosaic, no white balance) the luminance is
taken, as ``ieISO12233`` does, from the demosaicked sensor RGB. docs/camera.md compares
the two measurements camera by camera.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.optimize

from benchmark.camera import isp, sensor
from benchmark.camera.acquisition import acquire
from benchmark.camera.calibration import calibrate, illuminant_spectrum
from benchmark.camera.lens import lens_otf
from benchmark.camera.pipeline import camera_extent, electron_rate
from benchmark.camera.spec import CameraSpec
from benchmark.camera.spec_optics import OpticsSpec
from benchmark.camera.spec_sensor import SensorSpec
from benchmark.measure.targets import slanted_edge_scene
from metricscenes.spectral import WAVELENGTHS_NM

LUMINANCE_WEIGHTS = np.array([0.3, 0.6, 0.1])
"""The e-SFR's luminance of camera R, G, B (ISETCam)."""


def luminance_weights(cfa: str = "RGGB") -> np.ndarray:
    """Weights of the camera channels (:func:`benchmark.camera.sensor.cfa_channels`) in the
    e-SFR's luminance: :data:`LUMINANCE_WEIGHTS` for a Bayer tile; the clear channel alone
    for RCCB and RCCC, whose unfiltered pixels are the sensor's luminance samples (R and B
    are sampled once per tile and carry colour, not detail)."""
    channels = sensor.cfa_channels(cfa)
    if "C" not in channels:
        return LUMINANCE_WEIGHTS
    return np.array([1.0 if c == "C" else 0.0 for c in channels])


def esf_mtf(image: np.ndarray, *, oversample: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """e-SFR of a near-vertical edge image (rows, cols).

    Returns:
        (frequency in cycles/pixel, MTF) up to 1 cycle/pixel.
    """
    img = np.asarray(image, dtype=float)
    rows, cols = img.shape
    deriv = np.diff(img, axis=1)
    if deriv.sum() < 0:
        deriv = -deriv
    x = np.arange(cols - 1) + 0.5  # the difference of pixels i, i+1 sits at i + 1/2
    y = np.arange(rows, dtype=float)
    centroid = (deriv * x).sum(1) / deriv.sum(1)
    fit = np.polyfit(y, centroid, 1)
    for _ in range(2):  # refine with a Hamming window centred on the fitted edge
        half = max(8, cols // 4)
        win = np.where(np.abs(x[None, :] - np.polyval(fit, y)[:, None]) < half,
                       0.54 + 0.46 * np.cos(np.pi * (x[None, :] - np.polyval(fit, y)[:, None]) / half), 0.0)
        centroid = (deriv * win * x).sum(1) / (deriv * win).sum(1)
        fit = np.polyfit(y, centroid, 1)
    # keep an integer number of phase cycles of the edge (ISO 12233:2017, sfrmat3),
    # so every quarter-pixel bin is sampled with the same density
    cycles = int(np.floor(rows * abs(fit[0])))
    if cycles >= 1:
        keep_rows = int(round(cycles / abs(fit[0])))
        first = (rows - keep_rows) // 2
        img, y, rows = img[first : first + keep_rows], y[first : first + keep_rows], keep_rows
    cos_a = 1.0 / np.hypot(1.0, fit[0])
    dist = (np.arange(cols)[None, :] - np.polyval(fit, y)[:, None]) * cos_a
    reach = 0.5 * cols * cos_a - abs(fit[0]) * rows * cos_a - 2.0  # fully covered distances
    if reach < 4:
        raise ValueError("edge ROI too small or edge too slanted for the e-SFR")
    keep = np.abs(dist) < reach
    idx = np.floor((dist[keep] + reach) * oversample).astype(int)
    n = int(np.floor(2 * reach * oversample))
    idx = np.minimum(idx, n - 1)
    counts = np.bincount(idx, minlength=n)
    ok = counts > 0
    # each bin's mean value sits at its samples' mean distance (not the bin centre):
    # re-interpolating removes the jitter of the few sample phases a bin holds
    pos = np.bincount(idx, weights=dist[keep], minlength=n)[ok] / counts[ok]
    val = np.bincount(idx, weights=img[keep], minlength=n)[ok] / counts[ok]
    centres = np.arange(n)
    esf = np.interp((centres + 0.5) / oversample - reach, pos, val)
    lsf = np.gradient(esf)
    lsf *= np.sign(lsf.sum()) or 1.0
    shift = n // 2 - int(round((lsf * centres).sum() / lsf.sum()))
    lsf = np.roll(lsf, shift) * np.hamming(n)
    mtf = np.abs(np.fft.rfft(lsf))
    mtf /= mtf[0]
    freq = np.fft.rfftfreq(n, d=1.0 / oversample)  # cycles/pixel
    step = 1.0 / oversample
    mtf /= np.sinc(2 * freq * step) * np.sinc(freq * step)  # central difference, bin width
    keep = freq <= 1.0
    return freq[keep], mtf[keep]


def mtf50(freq: np.ndarray, mtf: np.ndarray) -> float:
    """First frequency where the MTF falls to 0.5 (linear interpolation): :func:`mtf_crossing` at 0.5."""
    return mtf_crossing(freq, mtf, 0.5)


def luminance_weights_per_band(sensor_spec: SensorSpec, spectrum: np.ndarray) -> np.ndarray:
    """How much each band contributes to the e-SFR luminance of an edge of this
    ``spectrum`` after white balance for it: w(λ) = Σ_c k_c g_c r_c(λ) S(λ), summing to 1."""
    resp = sensor.channel_responsivity(sensor_spec) * np.asarray(spectrum)[None, :]
    gains = resp.sum(1)[1] / resp.sum(1)
    w = (luminance_weights(sensor_spec.cfa) * gains) @ resp
    return w / w.sum()


def mtf50_analytic_cy_per_mm(
    pixel_um: float,
    f_number: float,
    wavelength_nm: float | None = None,
    *,
    sensor_spec: SensorSpec | None = None,
    spectrum: np.ndarray | None = None,
    optics: OpticsSpec | None = None,
) -> float:
    """MTF50 (cycles/mm) of the lens's OTF × square-pixel aperture (sinc, fill factor 1),
    along the horizontal frequency axis (what a near-vertical edge measures).

    The lens is ``optics`` (:func:`benchmark.camera.lens.lens_otf`: aberrations, measured
    tables and veiling glare included), by default the diffraction-limited lens at
    ``f_number``. With ``wavelength_nm`` the OTF is monochromatic. Without it (default) it
    is polychromatic: the per-band OTFs weighted by :func:`luminance_weights_per_band`
    (IMX363 QE × IR-cut, D65 edge unless given) — exact for the noise-free linear
    luminance the e-SFR measures, because that luminance is a fixed linear combination
    of the bands. Demosaicking is not modelled. The first crossing of 0.5 is returned.
    """
    # the ideal lens at f_number, unvalidated: the oracle also serves limits such as f/0.001
    lens = optics if optics is not None else OpticsSpec.model_construct(f_number=float(f_number))
    pixel_mm = pixel_um * 1e-3
    if wavelength_nm is not None:
        wl, w = np.array([float(wavelength_nm)]), np.array([1.0])
    else:
        spec = sensor_spec or SensorSpec(pixel_um=pixel_um)
        illum = illuminant_spectrum("D65") if spectrum is None else spectrum
        wl, w = WAVELENGTHS_NM, luminance_weights_per_band(spec, illum)

    def excess(f):
        """|polychromatic OTF| × pixel sinc − 0.5 at horizontal frequencies ``f``."""
        f = np.atleast_1d(np.asarray(f, float))
        h = sum(wi * lens_otf(lens, li, f, np.zeros(1))[0] for wi, li in zip(w, wl))
        return np.abs(h) * np.sinc(f * pixel_mm) - 0.5

    # A pupil passes nothing beyond its cutoff; the pixel sinc is zero at 1 / pixel.
    hi = 1.0 / pixel_mm
    if lens.psf_table is None and lens.mtf_table is None:
        hi = min(1.0 / (wl.min() * 1e-6 * lens.f_number), hi)
    grid = np.linspace(1e-6, hi, 257)
    below = np.nonzero(excess(grid) < 0)[0]
    if below.size == 0:
        return float("nan")
    k = below[0]
    if k == 0:
        return float(grid[0])
    return float(scipy.optimize.brentq(lambda f: float(excess(f)[0]), grid[k - 1], grid[k]))


ISETCAM_EDGE_ANGLE_DEG = math.degrees(math.atan(1.0 / 2.6))
"""Tilt from vertical of ISETCam's slanted bar, 21.04° (ISET/isetcam
``scene/pattern/sceneSlantedBar.m``: the edge is y = 2.6 x)."""
ISETCAM_ROI_PX = (96, 64)
"""(rows, cols) of the ``esfr="isetcam"`` window: ISETCam's ``ISOFindSlantedBar`` takes
a rect 1.5× taller than wide around the edge (the paper's were about 56 × 37 to
78 × 52 pixels; over 37–64 columns the MTF50 moves by < 3 %)."""


def _ahamming(n: int, mid: float) -> np.ndarray:
    # Burns's asymmetric Hamming window, ISO12233v1's ahamming (1-based positions)
    i = np.arange(1, n + 1)
    return 0.54 + 0.46 * np.cos(np.pi * (i - mid) / max(mid - 1.0, n - mid))


def _mround(x: float) -> int:
    # MATLAB round: halves away from zero
    return int(math.copysign(math.floor(abs(x) + 0.5), x))


def esf_mtf_isetcam(image: np.ndarray, *, oversample: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """ISETCam's e-SFR (ISET/isetcam ``metrics/ISO/ISO12233v1.m``, Burns's 2002 sfrmat
    as rewritten by ImagEval; ``ISO12233.m`` until ISETCam moved to sfrmat4), ported
    line by line for a near-vertical edge:

    * per-row derivative [½, −½], centroids under a Hamming window, a linear fit
      x = a + b·y, refined once with windows centred on the fit;
    * every pixel binned at ¼ pixel by its *horizontal* distance x − b·y from the edge
      (no cos θ correction: on a tilted edge the frequency axis is stretched by
      1/cos θ, 7 % at ISETCam's 21°);
    * central difference [½, 0, −½], shift to the centroid, symmetric Hamming window
      over the 4 × cols samples, |FFT| normalised at DC; no correction for the
      difference or the bin width (ISO 12233:2017's derivative correction).

    Returns:
        (frequency in cycles/pixel, MTF) up to 1 cycle/pixel.
    """
    img = np.asarray(image, dtype=float)
    if img.shape[1] > img.shape[0]:  # ISETCam's rotatev: the edge runs along the long side
        img = img.T
    rows, cols = img.shape
    fil1, fil2 = np.array([0.5, -0.5]), np.array([0.5, 0.0, -0.5])
    if img[:, :5].sum() > img[:, cols - 6 :].sum():  # the derivative must be positive
        fil1, fil2 = -fil1, -fil2
    d = fil1[0] * img[:, 1:] + fil1[1] * img[:, :-1]
    lsf_rows = np.concatenate([d[:, :1], d], axis=1)
    pos = np.arange(1, cols + 1)

    def centroids(window: np.ndarray) -> np.ndarray:
        w = lsf_rows * window
        return (w * pos).sum(1) / w.sum(1) - 0.5

    y = np.arange(rows)
    fit = np.polyfit(y, centroids(_ahamming(cols, (cols + 1) / 2)), 1)
    place = fit[1] + fit[0] * np.arange(1, rows + 1)  # 1-based rows, as in ISO12233v1
    fit = np.polyfit(y, centroids(np.stack([_ahamming(cols, p) for p in place])), 1)

    n = cols * oversample
    offset = _mround(-oversample * (rows - 1) * fit[0])
    span = abs(offset)
    offset = min(offset, 0)
    bins = (np.ceil((np.arange(cols)[None, :] - y[:, None] * fit[0]) * oversample) - offset).astype(int)
    length = n + span + 100
    counts = np.bincount(bins.ravel(), minlength=length)
    sums = np.bincount(bins.ravel(), weights=img.ravel(), minlength=length)
    start = _mround(0.5 * span)
    c, s = counts[start : start + n].astype(float), sums[start : start + n]
    esf = np.divide(s, c, out=np.zeros(n), where=c > 0)  # an empty bin reads 0, as there

    lsf = np.zeros(n)
    lsf[2:] = fil2[0] * esf[2:] + fil2[2] * esf[:-2]
    lsf[1] = lsf[2]
    centre = (np.arange(1, n + 1) * lsf).sum() / lsf.sum()
    shift = _mround(_mround(centre) - _mround((n + 1) / 2))
    centred = np.zeros(n)
    if shift > 0:
        centred[: n - shift] = lsf[shift:]
    else:
        centred[-shift:] = lsf[: n + shift]
    spectrum = np.abs(np.fft.fft(centred * _ahamming(n, (n + 1) / 2)))
    keep = _mround((n // 2 + 1) / 2)
    freq = oversample * np.arange(keep) / n
    return freq, spectrum[:keep] / spectrum[0]


def mtf50_isetcam(freq_cy_per_mm: np.ndarray, mtf: np.ndarray, nyquist_cy_per_mm: float,
                  step_cy_per_mm: float = 0.2) -> float:
    """ISETCam's MTF50 (``ISO12233v1.m``): the MTF below Nyquist, linearly interpolated
    every 0.2 cycles/mm, and the grid frequency whose MTF is *closest* to 0.5 (not the
    first crossing: an MTF that stays above 0.5 gives about the Nyquist frequency)."""
    below = freq_cy_per_mm < nyquist_cy_per_mm
    grid = np.arange(0.0, nyquist_cy_per_mm + 1e-9, step_cy_per_mm)
    f, m = freq_cy_per_mm[below], mtf[below]
    values = np.interp(grid, f, m, left=np.nan, right=np.nan)
    return float(grid[np.nanargmin(np.abs(values - 0.5))])


def measure_mtf50(
    camera: CameraSpec,
    *,
    roi_px: tuple[int, int] | None = None,
    angle_deg: float | None = None,
    esfr: str = "iso",
) -> dict:
    """Measured MTF50 of ``camera``: a D65 grey slanted edge through its optics, sensor
    (noise off, quantised) and demosaic, luminance e-SFR.

    White balance: D65 gains on the mosaic, or none where ``camera.isp.white_balance``
    is ``none`` (ISETCam's ``ieISO12233`` reads the demosaicked, unbalanced 'sensor
    space'). The colour matrix and the sRGB curve are never applied: the luminance is
    taken from linear camera RGB. ``esfr``: ``iso`` (:func:`esf_mtf`, a 5° edge in a
    96 × 192 window) or ``isetcam`` (:func:`esf_mtf_isetcam` and :func:`mtf50_isetcam`
    on ISETCam's 21° edge in a 96 × 64 window); ``roi_px``/``angle_deg`` override.

    Returns:
        dict with ``mtf50_cy_per_mm``, ``mtf50_cy_per_px``, ``freq_cy_per_mm`` and ``mtf``.
    """
    if esfr not in ("iso", "isetcam"):
        raise ValueError(f"unknown e-SFR {esfr!r} (allowed: iso, isetcam)")
    iset = esfr == "isetcam"
    roi_px = roi_px or (ISETCAM_ROI_PX if iset else (96, 192))
    if angle_deg is None:
        angle_deg = ISETCAM_EDGE_ANGLE_DEG if iset else 5.0
    d65 = illuminant_spectrum("D65")
    scene, extent = slanted_edge_scene(
        camera.width_px, camera.height_px, d65 * 1e-3, roi_px=roi_px, angle_deg=angle_deg, field=camera_extent(camera)
    )
    rate = sensor.mosaic(electron_rate(scene, camera, shape_px=roi_px, extent=extent), camera.sensor.cfa)
    # The camera's own acquisition (its HDR pixel, merge and companding included), noise off,
    # with the edge's peak at 90 % of the range; then its ISP up to the demosaicked channels.
    policy = camera.exposure.model_copy(update={"mode": "auto_peak", "level": 0.9, "region_fraction": 1.0})
    raw = acquire(rate, camera.model_copy(update={"exposure": policy}), seed=0, noise=False)
    processing = camera.isp if camera.isp.white_balance == "none" else camera.isp.model_copy(
        update={"white_balance": "known_illuminant", "illuminant": "D65"})
    rgb = isp.white_balanced_rgb(raw.linear_dn, camera.sensor, processing, calibrate(camera.sensor, processing))
    lum = rgb @ luminance_weights(camera.sensor.cfa)
    pixel_mm = camera.pixel_um * 1e-3
    if iset:
        freq, mtf = esf_mtf_isetcam(lum[4:-4, 4:-4])  # drop the demosaic's border
        per_px = mtf50_isetcam(freq / pixel_mm, mtf, 0.5 / pixel_mm) * pixel_mm
    else:
        freq, mtf = esf_mtf(lum[4:-4, 4:-4])  # drop the demosaic's border
        per_px = mtf50(freq, mtf)
    return {
        "mtf50_cy_per_mm": per_px / pixel_mm,
        "mtf50_cy_per_px": per_px,
        "freq_cy_per_mm": freq / pixel_mm,
        "mtf": mtf,
    }


MTF50_SOURCES = ("measured", "analytic", "published_group")
"""Where a camera's MTF50 comes from, in the order the one policy (:func:`camera_mtf50`)
tries them: the slanted edge through the camera (:func:`measure_mtf50`), diffraction ×
pixel aperture (:func:`mtf50_analytic_cy_per_mm`), the paper's MTF50 group of a registry
camera (``mtf50_group_cy_per_mm``). ``none``: no source gave a finite value."""


def camera_mtf50(camera: CameraSpec, prefer: str = "measured") -> tuple[float | None, str]:
    """(MTF50 in cycles/mm on the sensor, its source): the first of :data:`MTF50_SOURCES`
    from ``prefer`` on that gives a finite value, else ``(None, "none")``. The one MTF50
    policy of sweeps, reports and leaderboard submissions."""
    if prefer not in MTF50_SOURCES:
        raise ValueError(f"MTF50 source must be one of {', '.join(MTF50_SOURCES)}, got {prefer!r}")
    for source in MTF50_SOURCES[MTF50_SOURCES.index(prefer):]:
        try:
            if source == "measured":
                value = measure_mtf50(camera)["mtf50_cy_per_mm"]
            elif source == "analytic":
                value = mtf50_analytic_cy_per_mm(camera.pixel_um, camera.f_number, sensor_spec=camera.sensor,
                                                 optics=camera.optics)
            else:
                value = camera.mtf50_group_cy_per_mm
        except (ValueError, RuntimeError):  # a camera the edge bench cannot image falls through
            continue
        if value is not None and math.isfinite(value):
            return float(value), source
    return None, "none"


MTF_LEVELS = (0.5, 0.3, 0.1)  # MTF50, MTF30, MTF10: read off every measured curve


def mtf_crossing(freq: np.ndarray, mtf: np.ndarray, level: float) -> float:
    """First frequency where the MTF falls below ``level`` (linear interpolation), in
    ``freq``'s unit; NaN where the curve starts below it or never falls that far.
    :func:`mtf50` is its 0.5 crossing. Arrays keep their dtype (float32 curves are read in float32)."""
    freq, mtf = np.asarray(freq), np.asarray(mtf)
    below = np.nonzero(mtf < level)[0]
    if below.size == 0 or below[0] == 0:
        return float("nan")
    i = below[0]
    return float(freq[i - 1] + (mtf[i - 1] - level) * (freq[i] - freq[i - 1]) / (mtf[i - 1] - mtf[i]))


def mtf_readings(freq_cy_per_mm: np.ndarray, mtf: np.ndarray, pixel_um: float) -> dict:
    """MTF50, MTF30 and MTF10 of a curve in cycles/mm and cycles/pixel, and the Nyquist
    frequency: ``{"mtf10_cy_per_mm": ..., "mtf10_cy_per_px": ..., ..., "nyquist_cy_per_mm": ...}``.
    A level the curve does not reach within the measured band (up to 1 cycle/pixel) is NaN."""
    pixel_mm = pixel_um * 1e-3
    out = {}
    for level in MTF_LEVELS:
        f = mtf_crossing(freq_cy_per_mm, mtf, level)
        out[f"mtf{round(level * 100)}_cy_per_mm"] = f
        out[f"mtf{round(level * 100)}_cy_per_px"] = f * pixel_mm
    out["nyquist_cy_per_mm"] = 0.5 / pixel_mm
    return out


def mtf_figure(curves: list[dict]):
    """A matplotlib figure of measured MTF curves, each ``{"name", "pixel_um",
    "freq_cy_per_mm", "mtf"}``: MTF against cycles/mm on the sensor, each camera's Nyquist
    frequency as a dotted line in its colour, its MTF50/30/10 marked on the curve, and a
    second x axis in cycles/pixel — on top where every camera has the same pixel pitch,
    else a second panel against cycles/pixel (where all the Nyquist lines are 0.5)."""
    import matplotlib.pyplot as plt

    pitches = {round(float(c["pixel_um"]), 6) for c in curves}
    shared = len(pitches) <= 1
    fig, axes = plt.subplots(1 if shared else 2, 1, figsize=(7, 4.5 if shared else 8), squeeze=False)
    ax = axes[0, 0]
    nyquists = [0.5e3 / c["pixel_um"] for c in curves] or [500.0]
    markers = {0.5: "o", 0.3: "s", 0.1: "^"}
    for c in curves:
        freq, mtf, pixel_mm = np.asarray(c["freq_cy_per_mm"]), np.asarray(c["mtf"]), c["pixel_um"] * 1e-3
        readings = mtf_readings(freq, mtf, c["pixel_um"])
        for a, scale in ((ax, 1.0), *(() if shared else ((axes[1, 0], pixel_mm),))):
            (line,) = a.plot(freq * scale, mtf, label=c["name"])
            a.axvline(0.5 / pixel_mm * scale, color=line.get_color(), lw=0.9, ls=":")
            for level in MTF_LEVELS:
                f = readings[f"mtf{round(level * 100)}_cy_per_mm"]
                if np.isfinite(f):
                    a.plot([f * scale], [level], markers[level], color=line.get_color(), ms=4)
    for a in axes[:, 0]:
        for level in MTF_LEVELS:
            a.axhline(level, color="grey", lw=0.6, ls="--")
            a.annotate(f"MTF{round(level * 100)}", (1.0, level), xycoords=("axes fraction", "data"),
                       xytext=(3, 0), textcoords="offset points", va="center", fontsize=7, color="grey")
        a.set(ylabel="MTF (luminance)", ylim=(0, 1.1))
        a.legend(ncol=2, fontsize=8, title="dotted: Nyquist", title_fontsize=7)
    ax.set(xlabel="cycles/mm on the sensor", xlim=(0, 1.2 * max(nyquists)))
    if shared:
        pixel_mm = curves[0]["pixel_um"] * 1e-3 if curves else 1e-3
        top = ax.secondary_xaxis("top", functions=(lambda f: f * pixel_mm, lambda p: p / pixel_mm))
        top.set_xlabel("cycles/pixel (Nyquist = 0.5)")
    else:
        axes[1, 0].set(xlabel="cycles/pixel (Nyquist = 0.5 for every camera)", xlim=(0, 0.6))
    fig.tight_layout()
    return fig
