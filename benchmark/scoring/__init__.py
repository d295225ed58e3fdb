"""Scoring: COCO AP per distance, OD50 (distance where AP = 0.5) and its bootstrap SD.

See docs/detection.md for the rules.
"""

from benchmark.scoring.ap import AP_SCORE_THRESHOLD, ap_by_distance, images_by_distance
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES, Od50Bootstrap, bootstrap_od50, resample_environments
from benchmark.scoring.detectability import detection_rates
from benchmark.scoring.od50 import format_od50, od50, od50_censoring

__all__ = ["AP_SCORE_THRESHOLD", "BOOTSTRAP_RESAMPLES", "Od50Bootstrap", "ap_by_distance", "bootstrap_od50", "detection_rates",
           "format_od50", "images_by_distance", "od50", "od50_censoring", "resample_environments"]
