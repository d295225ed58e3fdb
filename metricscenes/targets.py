"""Conditions set by a photometric target: the mean image-plane illuminance of an ideal lens.

Liu et al. (EI 2023, sec. 3.1) state their conditions by their mean illuminance — daylight
"around 10–200 lux", night "around 0.1–1 lux" — made "by systematically varying the scene
luminance and adding headlights to the cars". A targeted condition does the same with a
collection's stored light groups (docs/scenes.md, "Conditions set by a photometric target"):

1. each environment draws its target T log-uniformly from the condition's range, seeded by
   the collection's seed, the environment and the condition's name (:func:`draw_target_lux`);
2. each scene's lamps keep their fixed weights and the ambient group's weight w is set so
   that the mix meets T over the whole field of view: the mean luminance of a mix is linear
   in the weights, L(w) = w L_ambient + Σ w_l L_l, and the image-plane illuminance of an
   ideal lens at f/N is E = π L / (1 + 4 N²) (:func:`ambient_weight`);
3. where the lamps alone exceed T, w = 0 and the scene records that it is over target.

Nothing is rendered again: L_ambient and L_l are the means of the stored groups' radiance.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np

from metricscenes.photometry import image_plane_illuminance_lux


def draw_target_lux(seed: int, environment_id: int, condition: str, lux_range: tuple[float, float]) -> float:
    """An environment's target (lux), log-uniform in ``lux_range`` and the same on every machine."""
    lo, hi = (float(v) for v in lux_range)
    name_key = int.from_bytes(hashlib.sha256(condition.encode()).digest()[:8], "little")
    u = np.random.default_rng([int(seed), int(environment_id), name_key]).random()
    return float(math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo))))


@dataclass(frozen=True)
class TargetedWeights:
    """A scene's weights under a targeted condition, and how they were found."""

    weights: dict[str, float]
    target_lux: float
    ambient_weight: float
    over_target: bool  # the lamps alone give more than the target: ambient weight 0
    lamps_lux: float  # the lamps' own mean image-plane illuminance

    def record(self) -> dict:
        return {"target_image_plane_lux": round(self.target_lux, 6), "ambient_weight": self.ambient_weight,
                "lamps_image_plane_lux": round(self.lamps_lux, 6), "over_target": self.over_target,
                "weights": dict(self.weights)}


def ambient_weight(target_lux: float, f_number: float, ambient_luminance: float,
                   lamp_luminances: dict[str, float], lamp_weights: dict[str, float],
                   ambient: str) -> TargetedWeights:
    """Weights that meet ``target_lux`` (mean image-plane illuminance at f/``f_number``):
    the lamps at their weights, ``ambient`` at what is left (0 if nothing is)."""
    lamps_luminance = sum(lamp_weights[g] * lamp_luminances[g] for g in lamp_weights)
    lamps_lux = image_plane_illuminance_lux(lamps_luminance, f_number)
    if ambient_luminance <= 0.0:
        raise ValueError(f"light group {ambient!r} adds no luminance here: it cannot set a target")
    needed = target_lux / image_plane_illuminance_lux(1.0, f_number) - lamps_luminance
    w = max(0.0, needed / ambient_luminance)
    weights = {ambient: w, **lamp_weights}
    return TargetedWeights(weights, target_lux, w, needed < 0.0, lamps_lux)
