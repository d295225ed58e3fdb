"""The camera wing: specifications and the registry of the paper's 13 cameras and the
extra (automotive) ones (here), the stages (lens, optics, distortion, sensor, exposure,
acquisition with dual_gain, isp, demosaic, calibration) and the pipeline that chains them
(:mod:`benchmark.camera.pipeline`)."""

from benchmark.camera.registry import (
    DATA_DIR,
    camera_from_dict,
    camera_names,
    extra_camera_names,
    list_cameras,
    load_camera,
)
from benchmark.camera.spec import CameraSpec
from benchmark.camera.spec_exposure import ExposureSpec
from benchmark.camera.spec_isp import ISPSpec
from benchmark.camera.spec_optics import OpticsSpec
from benchmark.camera.spec_sensor import SensorSpec

__all__ = [
    "DATA_DIR",
    "CameraSpec",
    "ExposureSpec",
    "ISPSpec",
    "OpticsSpec",
    "SensorSpec",
    "camera_from_dict",
    "camera_names",
    "extra_camera_names",
    "list_cameras",
    "load_camera",
]
