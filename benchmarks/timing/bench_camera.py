"""Time the camera simulation, stage by stage, against the previous implementation.

    PYTHONPATH=. python benchmarks/timing/bench_camera.py [--cameras cam10 cam08] [--repeat 3]

The input is a realistic two-layer scene: a 480 × 270 31-band plate over the whole
field of view and a 300 × 200 inset at 0.114 mrad per pixel (the generator's inset
sampling) near the centre. For each camera every stage runs ``--repeat`` times,
alternating with the baseline (the implementation before the speed work, kept below:
band-last float64 sparse resampling composited over the full frame, per-band strided
extraction + ``np.pad`` + tabulated OTF + per-channel accumulation, float64 sensor
temporaries with the fixed pattern drawn per capture, colour-demosaicing's float64
Malvar); the best time of each is reported, with the load average, since the
development machine is shared. ``--reference`` adds the plain per-band irradiance
path (31 forward + 31 inverse FFTs, then spectral integration). A naive per-band
spatial convolution with the lens's PSF is timed too (two bands, scaled to 31).
``--lenses`` times the optics stage for other lenses of the same camera: Zernike
defocus + spherical (rotationally symmetric: cached half-grid OTFs), astigmatism + coma
(complex OTFs, computed band by band) and 3 % veiling glare.

The optics stage is the production path: the lazy optical image
(:class:`benchmark.camera.optics.OpticalImage`) integrated by the sensor
(:func:`benchmark.camera.sensor.electron_rate`). Every OTF here, the baseline's table
and the naive PSF included, comes from :mod:`benchmark.camera.lens`.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import colour_demosaicing
import numpy as np
import scipy.fft as sfft
import scipy.ndimage

from benchmark.camera import calibration, exposure, isp, lens, optics, sensor
from benchmark.camera.pipeline import simulate
from benchmark.camera import load_camera
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene, _overlap_matrix, _weights
from metricscenes.spectral import WAVELENGTHS_NM


def two_layer_scene(seed: int = 0) -> SpectralScene:
    """Smooth random 31-band plate (480 × 270) and a finer 300 × 200 inset."""
    rng = np.random.default_rng(seed)
    basis = np.stack([np.exp(-0.5 * ((WAVELENGTHS_NM - c) / 40.0) ** 2) for c in (450, 550, 630)]).astype(np.float32)

    def cube(rows: int, cols: int, sigma: float) -> np.ndarray:
        base = scipy.ndimage.gaussian_filter(rng.random((rows, cols, 3), dtype=np.float32), (sigma, sigma, 0))
        return np.ascontiguousarray(base @ basis * np.float32(0.02), dtype=np.float32)

    e, pitch = REFERENCE_EXTENT, 0.114e-3
    x0, y0 = e.x0 + 0.52 * e.width, e.y0 + 0.5 * e.height
    inset = TanExtent(x0, y0, x0 + 300 * pitch, y0 + 200 * pitch)
    return SpectralScene(layers=(RadianceLayer(cube(270, 480, 1.0), e), RadianceLayer(cube(200, 300, 2.0), inset)))


# --- the previous implementation (baseline) --------------------------------------------------------


def old_resample(scene: SpectralScene, cols: int, rows: int) -> np.ndarray:
    def apply(wy, wx, cube):
        r_in, c_in, bands = cube.shape
        tmp = (wy @ cube.reshape(r_in, c_in * bands)).reshape(-1, c_in, bands).transpose(1, 0, 2).reshape(c_in, -1)
        return np.ascontiguousarray((wx @ tmp).reshape(wx.shape[0], -1, bands).transpose(1, 0, 2), dtype=np.float32)

    e = scene.extent
    out = apply(*_weights(scene.layers[0], cols, rows, e), scene.layers[0].radiance)
    for inset in scene.layers[1:]:
        cx = _overlap_matrix(inset.extent.x0, inset.extent.x1, inset.radiance.shape[1], e.x0, e.x1, cols)
        cy = _overlap_matrix(inset.extent.y0, inset.extent.y1, inset.radiance.shape[0], e.y0, e.y1, rows)
        cov = np.outer(np.asarray(cy.sum(axis=1)).ravel(), np.asarray(cx.sum(axis=1)).ravel())
        values = apply(*_weights(inset, cols, rows, e), inset.radiance)
        out = out * (1.0 - cov[..., None]).astype(np.float32) + values * cov[..., None].astype(np.float32)
    return out


# the ideal lens's OTF H(ν / ν_c) tabulated over ν / ν_c in [0, 1] (λ N = 1 mm: ν_c = 1 cy/mm)
_TABLE = lens.diffraction_otf(np.linspace(0.0, 1.0, 16385), 1e6, 1.0).astype(np.float32)


def old_channel_signal(radiance, wavelengths_nm, opt, pixel_um, responsivity):
    rows, cols, bands = radiance.shape
    resp = np.asarray(responsivity, float) * optics.irradiance_per_radiance(opt.f_number, opt.transmittance)
    pad = optics.pad_px(pixel_um, opt.f_number, float(np.max(wavelengths_nm)))
    shape = optics._padded_shape(rows, cols, pad)
    half = shape[0] // 2 + 1
    fy = np.abs(sfft.fftfreq(shape[0], d=pixel_um * 1e-3)[:half, None])
    rho = np.hypot(sfft.rfftfreq(shape[1], d=pixel_um * 1e-3)[None, :], fy).astype(np.float32)
    otf = np.empty((shape[0], shape[1] // 2 + 1), np.float32)
    acc = np.zeros((resp.shape[0],) + otf.shape, np.complex64)
    tmp = np.empty_like(acc[0])
    n = len(_TABLE) - 1
    for b in range(bands):
        spec = sfft.rfft2(optics._pad(radiance[:, :, b], pad, shape), workers=optics.FFT_WORKERS)
        idx = np.minimum(rho * np.float32(wavelengths_nm[b] * 1e-6 * opt.f_number * n), n) + 0.5
        top = _TABLE.take(idx.astype(np.int32))
        otf[:half], otf[half:] = top, top[1 : shape[0] - half + 1][::-1]
        spec *= otf
        for c in range(resp.shape[0]):
            np.multiply(spec, np.float32(resp[c, b]), out=tmp)
            acc[c] += tmp
    out = np.empty((resp.shape[0], rows, cols), np.float32)
    for c in range(resp.shape[0]):
        out[c] = sfft.irfft2(acc[c], s=shape, workers=optics.FFT_WORKERS)[pad : pad + rows, pad : pad + cols]
    return out


def old_capture_dn(rate, exposure_s, s, rng):
    e = rate.astype(np.float64) * exposure_s + s.dark_current_e_per_s * exposure_s
    e = np.minimum(rng.poisson(np.maximum(e, 0.0)).astype(np.float64), s.well_capacity_e)
    v = (e + s.read_noise_e * rng.standard_normal(e.shape)) * (s.conversion_gain_uv_per_e * 1e-6)
    g = np.random.default_rng([s.fpn_seed, 0x5E45])
    gain = 1.0 + s.prnu_fraction * g.standard_normal(v.shape, dtype=np.float32)
    v = v * gain + s.dsnu_v * g.standard_normal(v.shape, dtype=np.float32)
    v = np.clip(v * s.analog_gain + s.black_level_dn * s.lsb_v, 0.0, s.voltage_swing_v)
    return np.clip(np.rint(v / s.lsb_v), 0, s.white_level_dn).astype(np.uint16)


def old_isp(raw, s, cfa="RGGB"):
    lin = isp.raw_to_linear(raw, s)
    idx = sensor.cfa_index(*lin.shape, cfa)
    means = np.array([lin[idx == c].mean(dtype=np.float64) for c in range(3)])
    rgb = colour_demosaicing.demosaicing_CFA_Bayer_Malvar2004(isp.apply_gains(lin, means[1] / means, cfa), cfa)
    m = calibration.color_matrix(s).astype(np.float32)
    return np.einsum("hwc,kc->hwk", np.asarray(rgb, np.float32), m, optimize=True)


# --- timing ---------------------------------------------------------------------------------------


def _pair(new, old, repeat: int) -> tuple[float, float, object, object]:
    """Best-of-``repeat`` times of ``new`` and ``old``, run alternately."""
    t_new = t_old = np.inf
    out_new = out_old = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out_new = new()
        t_new = min(t_new, time.perf_counter() - t0)
        if old is not None:
            t0 = time.perf_counter()
            out_old = old()
            t_old = min(t_old, time.perf_counter() - t0)
    return t_new, t_old, out_new, out_old


LENSES = (
    ("Zernike defocus 0.2 + spherical 0.05 waves", {"zernike_waves": ((4, 0.2), (12, 0.05))}),
    ("Zernike astigmatism 0.15 + coma 0.1 waves", {"zernike_waves": ((5, 0.15), (8, 0.1))}),
    ("veiling glare 3 %", {"veiling_glare_fraction": 0.03}),
)
"""Other lenses timed by ``--lenses`` (the camera's lens with these fields changed)."""


def bench_camera(name: str, scene: SpectralScene, repeat: int, reference: bool, lenses: bool = False) -> None:
    cam = load_camera(name)
    rows, cols = cam.height_px, cam.width_px
    resp = sensor.channel_responsivity(cam.sensor)
    simulate(scene, cam, seed=0)  # warm the caches (OTFs, fixed pattern, colour matrix)
    rows_out: list[tuple[str, float, float]] = []

    t, t0, rad, rad_old = _pair(lambda: scene.resample(cols, rows), lambda: old_resample(scene, cols, rows), repeat)
    rows_out.append(("resample", t, t0))
    t, t0, chans, chans_old = _pair(
        lambda: sensor.electron_rate(optics.OpticalImage(rad, WAVELENGTHS_NM, cam.pixel_um, cam.optics), cam.sensor),
        lambda: old_channel_signal(rad_old, WAVELENGTHS_NM, cam.optics, cam.pixel_um, resp),
        repeat,
    )
    rows_out.append(("optics", t, t0))
    rate = sensor.mosaic(chans)
    t, t0, t_exp, _ = _pair(lambda: exposure.exposure_time_s(sensor.mosaic(chans), cam.sensor, cam.exposure), None, repeat)
    rows_out.append(("mosaic + exposure", t, t))
    t, t0, raw, _ = _pair(
        lambda: sensor.capture_dn(rate, t_exp, cam.sensor, np.random.default_rng(0)),
        lambda: old_capture_dn(rate, t_exp, cam.sensor, np.random.default_rng(0)),
        repeat,
    )
    rows_out.append(("sensor (noise, ADC)", t, t0))
    t, t0, lin, lin_old = _pair(lambda: isp.process(raw, cam.sensor, cam.isp, calibration.calibrate(cam.sensor, cam.isp)), lambda: old_isp(raw, cam.sensor), repeat)
    rows_out.append(("isp (wb, demosaic, matrix)", t, t0))
    t, _, _, _ = _pair(lambda: isp.encode_srgb8(lin), None, repeat)
    rows_out.append(("srgb encode", t, t))
    t_sim, _, _, _ = _pair(lambda: simulate(scene, cam, seed=0), None, repeat)

    print(f"\ncamera {cam.name}: {cols}x{rows} px, 31 bands, f/{cam.f_number}, pixel {cam.pixel_um} um, "
          f"load average {os.getloadavg()[0]:.1f}")
    print(f"{'stage':<30}{'new s':>9}{'baseline s':>12}{'speed-up':>10}")
    for stage, t, t0 in rows_out:
        print(f"{stage:<30}{t:>9.3f}{t0:>12.3f}{t0 / t:>9.1f}x")
    new_sum, old_sum = sum(r[1] for r in rows_out), sum(r[2] for r in rows_out)
    print(f"{'sum of stages':<30}{new_sum:>9.3f}{old_sum:>12.3f}{old_sum / new_sum:>9.1f}x")
    print(f"{'simulate() end to end':<30}{t_sim:>9.3f}")
    print(f"agreement with the baseline: radiance max rel {np.abs(rad - rad_old).max() / rad_old.max():.1e}, "
          f"channels max rel {np.abs(chans - chans_old).max() / chans_old.max():.1e}, "
          f"linear sRGB max abs {np.abs(lin - lin_old).max():.1e}")
    t_naive = naive_convolution_s(rad, cam)
    print(f"naive baseline, per-band spatial convolution with the lens's PSF (2 bands timed, x31/2): "
          f"{t_naive:.1f} s = {t_naive / rows_out[1][1]:.0f}x the optics")
    if lenses:
        for label, update in LENSES:
            other = cam.optics.model_copy(update=update)
            t_lens, _, _, _ = _pair(lambda: sensor.electron_rate(optics.OpticalImage(rad, WAVELENGTHS_NM, cam.pixel_um,
                                                                                     other), cam.sensor), None, repeat)
            print(f"optics, {label:<44}{t_lens:>7.3f} s ({t_lens / rows_out[1][1]:.1f}x the ideal lens)")
    if reference:
        t_ref, _, _, _ = _pair(
            lambda: np.einsum("hwb,cb->chw", optics.irradiance(rad, WAVELENGTHS_NM, cam.optics, cam.pixel_um),
                              resp.astype(np.float32), optimize=True), None, 1)
        print(f"reference per-band irradiance + integration: {t_ref:.3f} s ({t_ref / rows_out[1][1]:.1f}x the optics)")


def lens_psf(cam, wavelength_nm: float, radius_px: int) -> np.ndarray:
    """The camera's lens PSF sampled at its pixel pitch over ±``radius_px``, unit sum: the
    inverse FFT of :func:`benchmark.camera.lens.lens_otf` on that grid."""
    size = 2 * radius_px + 1
    pixel_mm = cam.pixel_um * 1e-3
    otf = lens.lens_otf(cam.optics, wavelength_nm, sfft.fftfreq(size, d=pixel_mm), sfft.fftfreq(size, d=pixel_mm))
    psf = np.fft.fftshift(np.real(np.fft.ifft2(otf)))
    return (psf / psf.sum()).astype(np.float32)


def naive_convolution_s(radiance: np.ndarray, cam) -> float:
    """Seconds a naive optics stage would take: each band convolved in space with its lens
    PSF (:func:`lens_psf`, out to 3 first-zero radii of the Airy pattern), timed on two
    bands (the shortest and longest wavelength) and scaled to 31."""
    spent = 0.0
    for band in (0, len(WAVELENGTHS_NM) - 1):
        lam_um = WAVELENGTHS_NM[band] * 1e-3
        radius_px = int(np.ceil(3 * 1.22 * lam_um * cam.f_number / cam.pixel_um))
        psf = lens_psf(cam, float(WAVELENGTHS_NM[band]), radius_px)
        plane = np.ascontiguousarray(radiance[..., band])
        t = time.perf_counter()
        scipy.ndimage.convolve(plane, psf, mode="reflect")
        spent += time.perf_counter() - t
    return spent * len(WAVELENGTHS_NM) / 2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cameras", nargs="+", default=["cam10", "cam08"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--reference", action="store_true", help="also time the per-band irradiance path")
    parser.add_argument("--lenses", action="store_true", help="also time the optics of aberrated and glaring lenses")
    args = parser.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, numpy {np.__version__}, "
          f"load average {' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    scene = two_layer_scene()
    for name in args.cameras:
        bench_camera(name, scene, args.repeat, args.reference, args.lenses)


if __name__ == "__main__":
    main()
