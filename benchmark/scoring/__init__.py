"""Scoring: COCO AP per distance, OD50 (distance where AP = 0.5), the AP range (area under
AP vs distance), their bootstrap over environments, the working threshold and the minimum sample.

See docs/scoring.md for the rules.
"""

from benchmark.scoring.ap import AP_SCORE_THRESHOLD, ap_by_distance, images_by_distance
from benchmark.scoring.ap_range import ap_range
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES, Od50Bootstrap, bootstrap_od50, enclose, resample_environments
from benchmark.scoring.detectability import FOUND_IOU, FOUND_SCORE, detection_rates, working_point
from benchmark.scoring.od50 import format_od50, od50, od50_censoring
from benchmark.scoring.sample import FEW_MARK, MIN_ENVIRONMENTS, few_footnote, mark_few, sample_too_small_text, too_few

__all__ = ["AP_SCORE_THRESHOLD", "BOOTSTRAP_RESAMPLES", "FEW_MARK", "FOUND_IOU", "FOUND_SCORE", "MIN_ENVIRONMENTS",
           "Od50Bootstrap", "ap_by_distance", "ap_range", "bootstrap_od50", "detection_rates", "enclose", "few_footnote", "format_od50",
           "images_by_distance", "mark_few", "od50", "od50_censoring", "resample_environments", "sample_too_small_text",
           "too_few", "working_point"]
