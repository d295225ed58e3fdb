"""MTF50 on ISETCam's terms, camera by camera: docs/data/mtf50-isp.csv (``benchmark publish
mtf50-isp``; docs/camera.md, "MTF50 on ISETCam's terms").

Per registry camera of the paper: its published MTF50 group, ISETCam's own curve read at its
pixel and f-number, and the e-SFR MTF50 three ways (``benchmark cameras mtf``): the project's
ISP and ISO e-SFR, ISETCam's default image processor (``--isp iset-parity``), and that ISP with
ISETCam's e-SFR and MTF50 rule (``--esfr isetcam``); the last two over the group; and the
analytic value (diffraction × pixel).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

ISETCAM_F_NUMBERS = (1.0, 3.0, 5.0, 7.0, 9.0, 11.0)
# ISETCam's MTF50 (c/mm) of its slanted bar through a diffraction-limited lens onto its default
# Bayer sensor, by pixel pitch (µm) and f-number: the curves the paper reads its groups off
# (ISET/isetauto, papers/EI2023/s_eiSensorFnumber.m, sensor-10.mat … sensor-42.mat).
ISETCAM_MTF50 = {
    1.0: (218.0, 155.6, 115.0, 90.2, 74.2, 63.4),
    1.4: (165.0, 131.0, 103.8, 84.4, 71.2, 61.4),
    2.1: (113.4, 98.8, 83.6, 72.2, 62.8, 55.2),
    2.8: (87.0, 77.8, 69.4, 62.0, 55.2, 49.0),
    3.5: (70.8, 64.2, 58.6, 53.4, 49.4, 44.8),
    4.2: (58.4, 54.8, 50.8, 47.2, 43.6, 40.4),
}


def isetcam_curve(pixel_um: float, f_number: float) -> float:
    """ISETCam's MTF50 (c/mm) at a pixel pitch of its curves, linear in f-number between them."""
    if pixel_um not in ISETCAM_MTF50:
        raise ValueError(f"no ISETCam curve for {pixel_um} µm pixels (it has {', '.join(map(str, ISETCAM_MTF50))})")
    return float(np.interp(f_number, ISETCAM_F_NUMBERS, ISETCAM_MTF50[pixel_um]))


def mtf50_isp_table(cameras) -> pd.DataFrame:
    """A row per camera (CameraSpecs with a published MTF50 group)."""
    from benchmark.camera.spec_isp import isp_preset
    from benchmark.measure.mtf import measure_mtf50, mtf50_analytic_cy_per_mm

    for cam in cameras:  # before measuring any
        if cam.mtf50_group_cy_per_mm is None:
            raise ValueError(f"{cam.name}: no published MTF50 group to compare with")
        isetcam_curve(cam.pixel_um, cam.f_number)
    parity = isp_preset("iset-parity")
    rows = []
    for cam in cameras:
        on_parity = cam.model_copy(update={"isp": parity})
        # in c/mm to 0.01, as `benchmark cameras mtf` gives them; the ratios are of these
        project, parity_isp, parity_esfr = (round(measure_mtf50(c, esfr=e)["mtf50_cy_per_mm"], 2)
                                            for c, e in ((cam, "iso"), (on_parity, "iso"), (on_parity, "isetcam")))
        group = cam.mtf50_group_cy_per_mm
        rows.append({
            "camera": cam.name, "pixel_um": cam.pixel_um, "f_number": cam.f_number, "paper_group_cy_per_mm": group,
            "isetcam_curve_cy_per_mm": round(isetcam_curve(cam.pixel_um, cam.f_number), 1),
            "project_mtf50_cy_per_mm": project, "parity_isp_mtf50_cy_per_mm": parity_isp,
            "parity_isetcam_esfr_mtf50_cy_per_mm": parity_esfr,
            "ratio_parity_isp_to_group": round(parity_isp / group, 3),
            "ratio_parity_isetcam_esfr_to_group": round(parity_esfr / group, 3),
            "analytic_cy_per_mm": round(mtf50_analytic_cy_per_mm(cam.pixel_um, cam.f_number, sensor_spec=cam.sensor,
                                                                 optics=cam.optics), 2),
        })
    return pd.DataFrame(rows)


def markdown(table: pd.DataFrame) -> str:
    """The table of docs/camera.md, "MTF50 on ISETCam's terms"."""
    lines = ["| camera | pixel µm | f/N | paper group | ISETCam curve | project | parity ISP | parity / group "
             "| parity ISP + ISETCam e-SFR | / group |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in table.itertuples():
        group = r.paper_group_cy_per_mm
        lines.append(f"| {r.camera} | {r.pixel_um:.1f} | {r.f_number:g} | {group:g} "
                     f"| {r.isetcam_curve_cy_per_mm:.1f} | {r.project_mtf50_cy_per_mm:.1f} | {r.parity_isp_mtf50_cy_per_mm:.1f} "
                     f"| {r.parity_isp_mtf50_cy_per_mm / group:.2f} | {r.parity_isetcam_esfr_mtf50_cy_per_mm:.1f} "
                     f"| {r.parity_isetcam_esfr_mtf50_cy_per_mm / group:.2f} |")
    return "\n".join(lines)
