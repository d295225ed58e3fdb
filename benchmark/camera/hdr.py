"""Two-exposure HDR: the merge of a long and a short raw, now part of the acquisition
strategies (:func:`benchmark.camera.acquisition.acquire_two_frames`). The names stay here
for code that imports them from this module."""

from benchmark.camera.acquisition import SWITCH_FRACTION, merge_two_exposures_dn, saturation_dn

__all__ = ["SWITCH_FRACTION", "merge_two_exposures_dn", "saturation_dn"]
