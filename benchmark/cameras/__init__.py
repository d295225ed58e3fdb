"""Camera specifications and the registry of the paper's 13 cameras."""

from benchmark.cameras.registry import DATA_DIR, camera_from_dict, camera_names, list_cameras, load_camera
from benchmark.cameras.spec import CameraSpec, ExposureSpec, ISPSpec, OpticsSpec, SensorSpec

__all__ = [
    "DATA_DIR",
    "CameraSpec",
    "ExposureSpec",
    "ISPSpec",
    "OpticsSpec",
    "SensorSpec",
    "camera_from_dict",
    "camera_names",
    "list_cameras",
    "load_camera",
]
