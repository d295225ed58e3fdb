"""benchmark: cameras, detectors and scores over metricscenes collections."""

import metricscenes  # noqa: F401  (first: it pins the numeric libraries' kernels before numpy loads)
