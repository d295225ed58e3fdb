"""Seeded planning: which car, road, skies and pose each environment gets.

The plan is a pure function of the manifest: environment ``e`` draws from its own
generator seeded by ``(manifest.seed, e)``, so adding environments never changes
the earlier ones, and the same manifest always gives the same plan. Each
environment is placed at every distance of the manifest (the paired design: within
an environment only the distance changes).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from metricscenes.manifest import Manifest

N_CARS = 50
N_ROADS = 20
SKY_IDS = {"day": range(0, 10), "dusk": range(10, 20), "night": range(20, 30)}
MAX_LATERAL_OFFSET_M = 0.4
MAX_YAW_DEG = 4.0


@dataclass(frozen=True)
class EnvironmentPlan:
    """One seeded draw of everything but the distance."""

    environment_id: int
    car_id: int
    road_id: int
    sky_day_id: int
    sky_dusk_id: int
    sky_night_id: int
    heading: str  # 'away': same lane as the camera, driving away; 'oncoming': facing the camera
    lateral_offset_m: float  # from the lane centre, + = left
    yaw_deg: float  # deviation from the lane direction
    seed: int  # render seed for this environment's plates

    @property
    def key(self) -> str:
        return f"env{self.environment_id:03d}"


@dataclass(frozen=True)
class ScenePlan:
    """One environment at one distance."""

    environment: EnvironmentPlan
    distance_m: float
    image_id: int
    seed: int  # render seed for this scene's inset

    @property
    def scene_id(self) -> str:
        return f"{self.environment.key}-d{int(round(self.distance_m)):03d}m"

    def summary(self) -> dict:
        env = asdict(self.environment)
        return {"scene_id": self.scene_id, "image_id": self.image_id, "distance_m": self.distance_m, **env}


def _derived_seed(*parts: int) -> int:
    return int(np.random.SeedSequence(list(parts)).generate_state(1, dtype=np.uint32)[0])


def plan_environment(manifest: Manifest, environment_id: int) -> EnvironmentPlan:
    rng = np.random.default_rng([manifest.seed, environment_id])
    return EnvironmentPlan(
        environment_id=environment_id,
        car_id=int(rng.integers(N_CARS)),
        road_id=int(rng.integers(N_ROADS)),
        sky_day_id=int(rng.choice(SKY_IDS["day"])),
        sky_dusk_id=int(rng.choice(SKY_IDS["dusk"])),
        sky_night_id=int(rng.choice(SKY_IDS["night"])),
        heading=str(rng.choice(["away", "oncoming"])),
        lateral_offset_m=round(float(rng.uniform(-MAX_LATERAL_OFFSET_M, MAX_LATERAL_OFFSET_M)), 3),
        yaw_deg=round(float(rng.uniform(-MAX_YAW_DEG, MAX_YAW_DEG)), 2),
        seed=_derived_seed(manifest.seed, environment_id, 0),
    )


def plan_collection(manifest: Manifest) -> list[ScenePlan]:
    """Every scene of the collection, environment-major, distances ascending."""
    scenes = []
    for e in range(manifest.environments):
        env = plan_environment(manifest, e)
        for k, d in enumerate(manifest.distances_m):
            scenes.append(
                ScenePlan(env, float(d), image_id=len(scenes) + 1,
                          seed=_derived_seed(manifest.seed, e, k + 1))
            )
    return scenes
