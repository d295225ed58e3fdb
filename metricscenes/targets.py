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

Two knobs change steps 2-3 (``TargetedCondition.scales``, ``target_at``; the paper's lab,
ISET/isetauto, made its conditions so): ``scales: mix`` scales the whole mix, lamps included,
its groups' weights fixed relative to one another, by s = T / E(mix) (:func:`mix_scale`), and
``target_at: camera`` meets T at each camera's own optical image: E is then what the camera
measures of each part's radiance through its own lens (``benchmark.camera.image_plane``), not
π L / (1 + 4 N²) of an ideal lens (:func:`solve_at_image_plane`).
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

    scales: str | None = None  # "mix": the whole mix scaled (None: the ambient group, as first made)
    mix_scale: float | None = None  # scales: mix: the factor on the mix's fixed weights
    mix_lux: float | None = None  # scales: mix: the mix's image-plane illuminance at its fixed weights
    at: dict | None = None  # target_at: camera: where it was met (the camera, its lens) and each part's lux

    def part_coefficients(self) -> dict[str, float]:
        """The factor on each of the condition's parts (``TargetedCondition.parts``): the mix's
        scale, or the ambient group's weight and 1 for the lamps at their own."""
        if self.scales == "mix":
            return {"mix": self.mix_scale}
        return {"ambient": self.ambient_weight, "lamps": 1.0}

    def record(self) -> dict:
        if self.scales == "mix":
            out = {"target_image_plane_lux": round(self.target_lux, 6), "scales": "mix", "mix_scale": self.mix_scale,
                   "mix_image_plane_lux": round(self.mix_lux, 6), "weights": dict(self.weights)}
        else:  # (the keys and values of the first targeted conditions: their results keep their bytes)
            out = {"target_image_plane_lux": round(self.target_lux, 6), "ambient_weight": self.ambient_weight,
                   "lamps_image_plane_lux": round(self.lamps_lux, 6), "over_target": self.over_target,
                   "weights": dict(self.weights)}
        if self.at is not None:
            out["target_at"] = dict(self.at)
        return out


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


def mix_scale(target_lux: float, mix_lux: float, mix: dict[str, float], where: str = "the mix") -> TargetedWeights:
    """The whole mix scaled to ``target_lux``: every group of ``mix`` at s × its fixed weight,
    s = T / ``mix_lux`` (its image-plane illuminance at the fixed weights), as ISETCam's
    ``oiAdjustIlluminance`` scales a whole optical image."""
    if not mix_lux > 0.0:
        raise ValueError(f"{where} adds no light here: it cannot meet a target")
    s = target_lux / mix_lux
    return TargetedWeights({g: s * w for g, w in mix.items()}, target_lux, 0.0, False, 0.0,
                           scales="mix", mix_scale=s, mix_lux=mix_lux)


def solve_at_image_plane(spec, target_lux: float, part_lux: dict[str, float], at: dict | None = None) -> TargetedWeights:
    """A targeted condition's weights from its parts' image-plane illuminances (lux, each part
    at its fixed weights: ``spec.parts()``), measured wherever the target applies: scaled
    whole (``scales: mix``), or the ambient group at what the lamps leave (0 if nothing),
    w = (T − E_lamps) / E_ambient. ``at``: recorded as where it was met."""
    from dataclasses import replace

    parts = spec.parts()
    if spec.scales_mix:
        return replace(mix_scale(target_lux, part_lux["mix"], parts["mix"]), at=at)
    ambient_lux, lamps_lux = part_lux["ambient"], part_lux.get("lamps", 0.0)
    if not ambient_lux > 0.0:
        raise ValueError(f"light group {spec.ambient!r} adds no light here: it cannot set a target")
    needed = target_lux - lamps_lux
    w = max(0.0, needed / ambient_lux)
    return TargetedWeights({spec.ambient: w, **parts["lamps"]}, target_lux, w, needed < 0.0, lamps_lux, at=at)
