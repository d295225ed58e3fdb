"""Input-size policies: how an image of any size is presented to the network.

- ``native`` — no resize: the image is padded with grey 114 to the next multiple of 32
  (centred for YOLOv5/YOLOv8, as YOLOv5 ``letterbox(auto=True)`` at the image's long side;
  bottom/right for YOLOX, its top-left convention). Needs a dynamic-shape model; a static
  model falls back to its fixed size with a warning.
- an integer (e.g. 640) — the family's letterbox to that square size (YOLOv5 ``auto=False``).
- ``multiscale`` — the reference policy: a native pass and a 640 pass, detections merged by
  class-wise NMS. A static model runs its fixed size only (with a warning).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

from benchmark.detectors.base import DetectorError

MULTISCALE_FIXED_PX = 640
# The command lines' one default (`benchmark run`, `sweep` and `detect`): the reference policy.
DEFAULT_INPUT_SIZE = "multiscale"
STRIDE = 32


@dataclass(frozen=True)
class Pass:
    """One inference pass: ``size_px`` None = native resolution padded to a multiple of 32."""

    size_px: int | None

    @property
    def label(self) -> str:
        return "native" if self.size_px is None else str(self.size_px)


def parse_input_size(value: str | int) -> str | int:
    """'native' | 'multiscale' | a positive multiple of 32 (ints may come as strings)."""
    if isinstance(value, str):
        v = value.strip().lower()
        if v in ("native", "multiscale"):
            return v
        if not v.isdigit():
            raise ValueError(f"input_size must be 'native', 'multiscale' or a multiple of 32, got {value!r}")
        value = int(v)
    if isinstance(value, bool) or not isinstance(value, int) or value <= 0 or value % STRIDE:
        raise ValueError(f"input_size must be 'native', 'multiscale' or a positive multiple of 32, got {value!r}")
    return value


def plan_passes(input_size: str | int, static_hw: tuple[int, int] | None, model_name: str) -> list[Pass]:
    """The passes a policy needs on a model (``static_hw`` = its fixed input, None if dynamic)."""
    policy = parse_input_size(input_size)
    if static_hw is None:
        if policy == "native":
            return [Pass(None)]
        if policy == "multiscale":
            return [Pass(None), Pass(MULTISCALE_FIXED_PX)]
        return [Pass(policy)]
    if static_hw[0] != static_hw[1]:
        raise DetectorError(f"{model_name}: non-square static input {static_hw} is not supported")
    fixed = static_hw[0]
    if policy in ("native", "multiscale"):
        warnings.warn(
            f"{model_name} has a static {fixed}x{fixed} input; policy '{policy}' falls back to {fixed} "
            "(use a dynamic-shape model for native resolution)",
            stacklevel=5,
        )
        return [Pass(fixed)]
    if policy != fixed:
        raise DetectorError(f"{model_name} has a static {fixed}x{fixed} input; input_size {policy} needs a dynamic-shape model")
    return [Pass(fixed)]
