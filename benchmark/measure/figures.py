"""What a camera spec implies: field of view, IFOV, Nyquist and MTF50 (cycles/mm on the
sensor and cycles/mrad in object space, through the whole chain), saturation, dynamic
range, SNR at a stated reference, the figures of an EMVA 1288 report measured on the
model's photon transfer (dynamic range, SNR10 and SNR1 illuminance, HDR transitions), and
warnings where the spec hides something (a well the gain makes unreachable, a value
outside what most sensors have). ``benchmark cameras show`` prints them (docs/camera.md,
"Field of view and geometry", "What a spec implies", "Datasheet figures"). It stands in
``measure``, above the camera, because its MTF50 and datasheet are measurements.

Every figure is computed from the spec with the pipeline's own formulas: saturation by
:func:`benchmark.camera.sensor.saturation_electrons`, the reference signal by
:func:`benchmark.camera.pipeline.electron_rate` on a uniform scene.
"""

from __future__ import annotations

import math

from benchmark.camera.exposure import reference_exposure_s
from benchmark.camera.spec import CameraSpec
from benchmark.camera.spec_rules import plausibility_warnings
from benchmark.camera.spec_sensor import MAX_CAPTURE_GIB

REFERENCE_ILLUMINANCE_LUX = 100.0
"""Illuminance of the SNR reference: a 18 % grey Lambertian surface lit by 100 lux of D65."""
REFERENCE_REFLECTANCE = 0.18
REFERENCE_ILLUMINANT = "D65"


def reference_signal_e_per_s(camera: CameraSpec) -> float:
    """Signal rate of a green pixel (clear, for RCCB and RCCC) on the axis, e⁻/s, viewing a 18 % grey Lambertian
    surface under 100 lux of D65 (luminance 0.18 × 100 / π cd/m²): the pipeline's optics
    and sensor response on a uniform scene, diffraction off (it does not change a
    uniform field)."""
    from benchmark.camera.pipeline import electron_rate
    from benchmark.camera.calibration import illuminant_spectrum
    from metricscenes.geometry import REFERENCE_EXTENT
    from metricscenes.photometry import radiance_to_xyz
    from metricscenes.radiance import SpectralScene

    spectrum = illuminant_spectrum(REFERENCE_ILLUMINANT)
    luminance = REFERENCE_REFLECTANCE * REFERENCE_ILLUMINANCE_LUX / math.pi
    radiance = spectrum * (luminance / float(radiance_to_xyz(spectrum)[1]))
    scene = SpectralScene.uniform(radiance, rows=8, cols=8)
    rate = electron_rate(scene, camera, shape_px=(8, 8), extent=REFERENCE_EXTENT, diffraction=False)
    return float(rate[1].mean())


def camera_figures(camera: CameraSpec) -> dict:
    """What the spec implies, as a JSON-ready dict (units in the keys). ``datasheet``: the
    figures of an EMVA 1288 report measured on the model's photon transfer
    (:func:`benchmark.measure.photon_transfer.datasheet_figures`); the rest from the spec's
    formulas. An HDR pixel (``sensor.dcg``): saturation is the top of the merged range, the
    noise floor the HCG readout's, and ``hdr_readouts`` lists the readouts."""
    from benchmark.camera import dual_gain
    from benchmark.camera.sensor import saturation_electrons, signal_volts_per_electron
    from benchmark.measure.mtf import camera_mtf50
    from benchmark.measure.photon_transfer import datasheet_figures

    s = camera.sensor
    mtf50, mtf50_source = camera_mtf50(camera)
    volts_per_e = signal_volts_per_electron(s)
    adc_e = (s.white_level_dn - s.black_level_dn) * s.lsb_v / volts_per_e
    saturation = saturation_electrons(s) if s.dcg is None else dual_gain.merged_saturation_e(s)
    e_per_dn = s.lsb_v / volts_per_e
    # Noise floor: read noise, DSNU (volts before the analog gain) and the ADC's LSB/√12.
    dsnu_e = s.dsnu_v / (s.conversion_gain_uv_per_e * 1e-6)
    floor = math.sqrt(s.read_noise_e**2 + dsnu_e**2 + e_per_dn**2 / 12.0)
    t = reference_exposure_s(camera)
    rate = reference_signal_e_per_s(camera)
    signal = min(rate * t, saturation)
    dark = s.dark_current_e_per_s * t
    if s.dcg is None:
        noise = math.sqrt(signal + dark + (s.prnu_fraction * signal) ** 2 + floor**2)
    else:  # the readout the merge takes at this signal: its shot and read noise
        noise = math.sqrt(dual_gain.temporal_variance_e2(s, signal) + dark + (s.prnu_fraction * signal) ** 2)
    snr = signal / noise if noise > 0 else math.inf
    limited_by = "adc" if adc_e < s.well_capacity_e else "well"
    if s.dcg is not None:
        last = dual_gain.readouts(s)[-1]
        limited_by = f"{last.name} {'well' if last.saturation_e >= last.well_capacity_e else 'adc'}"
    return {
        "focal_length_mm": camera.optics.focal_length_mm,
        "size_px": [camera.width_px, camera.height_px],
        "pixel_array_mm": [round(s.array_width_mm, 6), round(s.array_height_mm, 6)],
        "fov_deg": {"horizontal": round(camera.hfov_deg, 4), "vertical": round(camera.vfov_deg, 4)},
        "ifov_mrad": round(camera.ifov_mrad, 6),
        "distortion_k1_k2": list(camera.optics.distortion) if camera.optics.distortion else None,
        "nyquist_cy_per_mm": round(camera.nyquist_cy_per_mm, 4),
        "nyquist_cy_per_mrad": round(camera.cy_per_mrad(camera.nyquist_cy_per_mm), 4),
        "mtf50": {"cy_per_mm": None if mtf50 is None else round(mtf50, 2),
                  "cy_per_mrad": None if mtf50 is None else round(camera.cy_per_mrad(mtf50), 4),
                  "source": mtf50_source},
        "saturation_e": round(saturation, 1),
        "saturation_limited_by": limited_by,
        "well_capacity_e": s.well_capacity_e,
        "adc_saturation_e": round(adc_e, 1),
        "e_per_dn": round(e_per_dn, 4),
        "noise_floor_e": round(floor, 3),
        "dynamic_range_db": round(20 * math.log10(saturation / floor), 2) if floor > 0 else None,
        "snr_reference": {
            "scene": f"{REFERENCE_REFLECTANCE:.0%} grey Lambertian, {REFERENCE_ILLUMINANCE_LUX:g} lux "
                     f"{REFERENCE_ILLUMINANT}, {'clear' if 'C' in s.cfa else 'green'} pixel on the axis, no ISP",
            "exposure_s": t,
            "signal_e": round(signal, 2),
            "clipped": rate * t > saturation,
            "snr": round(snr, 3),
            "snr_db": round(20 * math.log10(snr), 2) if 0 < snr < math.inf else None,
        },
        "capture_memory_gib": round(s.capture_memory_bytes / 2**30, 3),
        **({} if s.dcg is None else {"hdr_readouts": [
            {"name": r.name, "conversion_gain_uv_per_e": r.conversion_gain_uv_per_e, "read_noise_e": r.read_noise_e,
             "saturation_e": round(r.saturation_e / r.sensitivity, 1), "takes_over_e": r.takes_over_e}
            for r in dual_gain.readouts(s)]}),
        "datasheet": datasheet_figures(camera),
    }


def camera_warnings(camera: CameraSpec, figures: dict | None = None) -> list[str]:
    """One line per thing the spec implies but does not say."""
    from benchmark.camera.pipeline import camera_extent
    from metricscenes.geometry import REFERENCE_EXTENT, extent_within, fov_deg

    f = figures or camera_figures(camera)
    s = camera.sensor
    out = []
    adc_e, well = f["adc_saturation_e"], s.well_capacity_e
    if s.dcg is not None:  # the HCG readout saturates by design: the merge hands its pixels on
        out.extend(companding_warnings(s))
    elif adc_e < well:
        usable_gain = s.analog_gain * adc_e / well
        out.append(f"the ADC clips at {adc_e:.0f} e- (voltage swing / (conversion gain x analog gain "
                   f"{s.analog_gain:.3g}), less the black level) before the {well:.0f} e- well fills: "
                   f"{1 - adc_e / well:.0%} of the well is unreachable (analog_gain <= {usable_gain:.3g} reaches it)")
    elif well < 0.99 * adc_e:
        dn = s.black_level_dn + well / f["e_per_dn"]
        out.append(f"the {well:.0f} e- well fills at {dn:.0f} DN, below the ADC white level {s.white_level_dn} DN: "
                   f"{1 - well / adc_e:.0%} of the codes above black are never used")
    for axis, written, px in (("width", s.active_width_mm, s.array_width_mm),
                              ("height", s.active_height_mm, s.array_height_mm)):
        if abs(written - px) > 1e-6 * written:
            out.append(f"active {axis} {written:g} mm is {written * 1000 / s.pixel_um:.2f} pixels of {s.pixel_um:g} um: "
                       f"the pixel array ({px:.6g} mm) sets the field of view")
    if not extent_within(camera_extent(camera), REFERENCE_EXTENT):
        fh, fv = fov_deg(REFERENCE_EXTENT)
        out.append(f"the field {camera.hfov_deg:.2f}° x {camera.vfov_deg:.2f}° exceeds the reference collection "
                   f"field {fh:.2f}° x {fv:.2f}°: runs on collections with that field are refused")
    if f["snr_reference"]["clipped"]:
        out.append("the SNR reference saturates at the reference exposure (the figure is at saturation)")
    if f["capture_memory_gib"] > MAX_CAPTURE_GIB / 2:
        out.append(f"one capture needs about {f['capture_memory_gib']:.1f} GiB")
    return out + plausibility_warnings(camera)


def companding_warnings(sensor) -> list[str]:
    """One line per companding segment the merged range reaches whose step (merged codes per
    output code) exceeds the merged signal's temporal noise where it starts: there the
    companding, not the light, sets the noise (docs/camera.md, "Acquisition")."""
    from benchmark.camera import dual_gain

    k = dual_gain.dn_per_electron(sensor, dual_gain.readouts(sensor)[0])
    top = sensor.black_level_dn + dual_gain.merged_saturation_e(sensor) * k
    knees = sensor.dcg.companding_knees
    out = []
    for (x0, y0), (x1, y1) in zip(knees[:-1], knees[1:]):
        step = (x1 - x0) / (y1 - y0)
        if x0 > top or step <= 1.0:
            continue
        noise = math.sqrt(dual_gain.temporal_variance_e2(sensor, max(x0 - sensor.black_level_dn, 0) / k)) * k
        if step > noise:
            out.append(f"sensor.dcg.companding_knees: the segment from merged code {x0} steps {step:.3g} codes, more "
                       f"than the temporal noise there ({noise:.3g} codes): the companding adds visible noise")
    return out


def figure_rows(figures: dict) -> list[tuple[str, str]]:
    """(label, value) rows of :func:`camera_figures` for a table."""
    snr = figures["snr_reference"]
    dr = figures["dynamic_range_db"]
    snr_text = (f"{snr['snr']:.1f} ({snr['snr_db']:.1f} dB)" if snr["snr_db"] is not None else "inf") + \
        f" at {snr['signal_e']:.0f} e-, {snr['exposure_s'] * 1e3:g} ms: {snr['scene']}"
    return [
        ("field of view", f"{figures['fov_deg']['horizontal']:.2f}° x {figures['fov_deg']['vertical']:.2f}° "
                          f"(f {figures['focal_length_mm']:g} mm, pixel array {figures['pixel_array_mm'][0]:.4g} x "
                          f"{figures['pixel_array_mm'][1]:.4g} mm"
                          + (", distortion k1 {:g}, k2 {:g}".format(*figures["distortion_k1_k2"])
                             if figures["distortion_k1_k2"] else "") + ")"),
        ("IFOV", f"{figures['ifov_mrad']:.4g} mrad per pixel (on the axis)"),
        ("Nyquist", f"{figures['nyquist_cy_per_mm']:.1f} cy/mm on the sensor, "
                    f"{figures['nyquist_cy_per_mrad']:.3f} cy/mrad in object space"),
        ("MTF50", _mtf50_text(figures["mtf50"], figures["focal_length_mm"])),
        ("saturation", f"{figures['saturation_e']:.0f} e- ({figures['saturation_limited_by']}; well "
                       f"{figures['well_capacity_e']:.0f} e-, ADC {figures['adc_saturation_e']:.0f} e-)"
         + ("" if "hdr_readouts" not in figures else "; merged range of the readouts " + ", ".join(
             f"{r['name']} {r['conversion_gain_uv_per_e']:g} uV/e- to {r['saturation_e']:.0f} e-"
             for r in figures["hdr_readouts"]))),
        ("dynamic range", (f"{dr:.1f} dB" if dr is not None else "inf") +
         f" (saturation / noise floor {figures['noise_floor_e']:.2f} e-: read, DSNU, LSB/sqrt(12))"),
        ("SNR reference", snr_text),
        ("memory per capture", f"about {figures['capture_memory_gib']:.2f} GiB"),
        *_datasheet_rows(figures["datasheet"]),
    ]


def _datasheet_rows(sheet: dict) -> list[tuple[str, str]]:
    """Rows of the photon-transfer figures (:func:`benchmark.measure.photon_transfer.datasheet_figures`)."""
    def lux(value):
        return "-" if value is None else f"{value:.3g} lux"

    rows = [
        ("photon transfer", sheet["method"]),
        ("measured DR", (f"{sheet['dynamic_range_db']:.1f} dB" if sheet["dynamic_range_db"] else "-") +
         f" (photon transfer: saturation {sheet['saturation_e']:.0f} e- / dark noise {sheet['dark_noise_e']:.3g} e-)"),
        ("SNR10", f"{lux(sheet['snr10_lux'])} at the sensor ({sheet['snr10_e'] or 0:.1f} e-; "
                  f"{sheet['electrons_per_lux_s']:.0f} e- per lux.s)"),
        ("SNR1", f"{lux(sheet['snr1_lux'])} at the sensor ({sheet['snr1_e'] or 0:.2f} e-)"),
        ("SNR max", f"{sheet['snr_max_db']:.1f} dB"),
    ]
    for t in sheet["transitions"]:
        after = "-" if t["snr_db_after"] is None else f"{t['snr_db_after']:.1f} dB"
        rows.append((f"HDR {t['from']} -> {t['to']}",
                     f"transition at {t['electrons'] or 0:.0f} e- of the large photodiode, {lux(t['lux'])} at "
                     f"the sensor; SNR {after} just after"))
    return rows


def _mtf50_text(mtf50: dict, focal_length_mm: float) -> str:
    """"229.3 cy/mm on the sensor, 1.004 cy/mrad in object space (× f 4.38 mm; measured)"."""
    if mtf50["cy_per_mm"] is None:
        return "- (no source gave one)"
    through = " through the whole chain: lens, sensor, acquisition, demosaic" if mtf50["source"] == "measured" else ""
    return (f"{mtf50['cy_per_mm']:.1f} cy/mm on the sensor, {mtf50['cy_per_mrad']:.3f} cy/mrad in object space "
            f"(x f {focal_length_mm:g} mm / 1000; {mtf50['source']}{through})")
