"""The minimum sample behind a verdict, and the mark of a figure from fewer environments.

The bootstrap resamples environments; each carries its scene and the capture noise of its
one image per distance, so the interval covers both — once there are enough environments for
the resamples to differ (docs/scoring.md, "What is resampled"). On two environments there are
three distinct resamples and the "95 %" interval is two or three values. Below
:data:`MIN_ENVIRONMENTS` environments per distance ``compare`` and ``report`` give no verdict
and say so in one line (:func:`sample_too_small_text`), and tables mark OD50 and AP range with
:data:`FEW_MARK` (:func:`mark_few`, footnote :func:`few_footnote`).

To change the number, change :data:`MIN_ENVIRONMENTS` here and the table of measurements
in docs/scoring.md ("Minimum sample") that sets it.
"""

from __future__ import annotations

MIN_ENVIRONMENTS = 5  # a floor against the degenerate bootstrap (docs/scoring.md, "Minimum sample")
"""Fewest environments per distance behind a verdict (compare, report) or an unmarked figure
(sweep, report, leaderboard tables); set from camera-vs-reseeded-camera comparisons
(docs/scoring.md, "Minimum sample")."""

FEW_MARK = "†"
"""Appended to an OD50 or AP range figure from fewer than :data:`MIN_ENVIRONMENTS` environments per distance."""


def too_few(n_environments) -> bool:
    """True where ``n_environments`` (per distance; None: unknown) is below :data:`MIN_ENVIRONMENTS`."""
    return n_environments is not None and n_environments == n_environments and int(n_environments) < MIN_ENVIRONMENTS


def sample_too_small_text(n_environments: int) -> str:
    """The one line that replaces a verdict on too few environments."""
    return (f"sample too small: {int(n_environments)} environments per distance, at least {MIN_ENVIRONMENTS} "
            "needed for a verdict (docs/scoring.md)")


def mark_few(text: str, n_environments) -> str:
    """``text`` with :data:`FEW_MARK` appended where the figure rests on too few environments."""
    return f"{text}{FEW_MARK}" if too_few(n_environments) and text not in ("", "–") else text


def few_footnote() -> str:
    """The footnote every table with :data:`FEW_MARK` carries."""
    return (f"{FEW_MARK} from fewer than {MIN_ENVIRONMENTS} environments per distance: too few for a verdict, "
            "shown but not compared (docs/scoring.md)")
