"""Scoring: COCO AP per distance, OD50 (distance where AP = 0.5) and its bootstrap SD.

See docs/detection.md for the rules.
"""

from benchmark.scoring.ap import ap_by_distance, images_by_distance
from benchmark.scoring.bootstrap import bootstrap_od50, resample_environments
from benchmark.scoring.detectability import detection_rates
from benchmark.scoring.od50 import od50

__all__ = ["ap_by_distance", "bootstrap_od50", "detection_rates", "images_by_distance", "od50",
           "resample_environments"]
