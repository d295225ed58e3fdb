"""Assemble a Mitsuba scene for one environment, one light group and one film.

The plate of an environment is its scene without the car; an inset adds the car.
A light group switches on only its own emitters: the sky of that kind, the car's
lamps, or the street lights (radiance is linear in emitter power, so a condition is
a weighted sum of the groups' renders).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from metricscenes.assets import cars, ego_vehicle, roads, skies
from metricscenes.assets.parts import SceneParts
from metricscenes.plan import EnvironmentPlan
from metricscenes.render import BLOCK_SIZE_PX, Film, sensor_dict

SKY_GROUPS = {"sky_day": "sky_day_id", "sky_dusk": "sky_dusk_id", "sky_night": "sky_night_id"}



@dataclass(frozen=True)
class CarPose:
    """Where the car stands: ground point under its centre (world m) and yaw (rad, 0 = facing +x)."""

    x_m: float
    y_m: float
    yaw_rad: float


def car_pose(env: EnvironmentPlan, distance_m: float) -> CarPose:
    """Place the environment's car ``distance_m`` ahead of the camera (to the car's centre).

    'away': in the camera's lane, driving away (we see its rear); 'oncoming': in the
    nearest oncoming lane, facing the camera (we see its front and head lamps).
    """
    road = roads.road_spec(env.road_id)
    lane_y = roads.lane_center_y_m(road, 0, "same" if env.heading == "away" else "oncoming")
    base_yaw = 0.0 if env.heading == "away" else math.pi
    return CarPose(
        x_m=float(distance_m),
        y_m=float(lane_y + env.lateral_offset_m),
        yaw_rad=base_yaw + math.radians(env.yaw_deg),
    )


def environment_parts(env: EnvironmentPlan, ground_to_horizon: bool = False,
                      road_end_m: float | None = None) -> SceneParts:
    """The road, its trees and street lights, and the camera vehicle's own head lamps
    (``ground_to_horizon``: see :func:`metricscenes.assets.roads.horizon_edge`; ``road_end_m``:
    where the detailed road ends, :func:`metricscenes.assets.roads.road_parts`)."""
    road = roads.road_parts(roads.road_spec(env.road_id), seed=env.seed, ground_to_horizon=ground_to_horizon,
                            road_end_m=road_end_m)
    return road.merged(ego_vehicle.ego_lamp_parts())


def car_parts(env: EnvironmentPlan, pose: CarPose, *, plate_lamp: bool = False,
              rear_retroreflectors: bool = False) -> SceneParts:
    """The environment's car at ``pose``, with its lit rear plate and its rear
    retro-reflectors where asked (:func:`metricscenes.assets.cars.car_parts`; the manifest's
    ``render.plate_lamp`` and ``render.rear_retroreflectors``)."""
    return cars.car_parts(cars.car_spec(env.car_id), (pose.x_m, pose.y_m), pose.yaw_rad,
                          plate_lamp=plate_lamp, rear_retroreflectors=rear_retroreflectors)


def car_vertices(env: EnvironmentPlan, pose: CarPose) -> np.ndarray:
    """All car mesh vertices in world metres (N, 3), for ground truth and inset windows."""
    return cars.car_vertices_world(cars.car_spec(env.car_id), (pose.x_m, pose.y_m), pose.yaw_rad)


def has_emitters(parts: SceneParts, light_group: str) -> bool:
    """Whether rendering ``light_group`` would put any light in these parts."""
    if light_group in SKY_GROUPS:
        return True
    return any(lamp.light_group == light_group for lamp in parts.lamps)


def scene_dict(
    env: EnvironmentPlan,
    parts: SceneParts,
    light_group: str | Sequence[str],
    film: Film,
    *,
    spp: int,
    seed: int,
    max_depth: int,
) -> dict:
    """A ``mi.load_dict``-ready scene lit by ``light_group`` alone, or by several groups
    (at most one sky: a scene holds one environment emitter)."""
    groups = (light_group,) if isinstance(light_group, str) else tuple(light_group)
    skies_on = [g for g in groups if g in SKY_GROUPS]
    if len(skies_on) > 1:
        raise ValueError(f"a scene holds one sky, got {skies_on}")
    scene: dict = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(max_depth), "block_size": BLOCK_SIZE_PX},
        "sensor": sensor_dict(film, spp, seed),
    }
    scene.update(parts.shapes)
    # Lamps are instantiated here, one by one: left as nested dicts, Mitsuba's loader
    # registers their emitters in a varying order, and the emitter sampler (hence the
    # image) then differs between identical runs.
    import mitsuba as mi

    for lamp in parts.lamps:
        on = lamp.light_group in groups
        if lamp.shape is not None:
            shape = dict(lamp.shape)
            if on:
                shape["emitter"] = lamp.emitter
            scene[f"lamp_{lamp.name}"] = mi.load_dict(shape)
        elif on:
            scene[f"lamp_{lamp.name}"] = mi.load_dict(lamp.emitter)
    for group in skies_on:
        sky = skies.sky_spec(getattr(env, SKY_GROUPS[group]))
        for key, emitter in skies.sky_emitters(sky).items():
            scene[f"sky_{key}"] = emitter
    return scene


def emitter_groups(scene_description: dict, loaded_scene, parts: SceneParts, light_groups: Sequence[str]) -> dict:
    """Each emitter of ``loaded_scene`` (loaded from ``scene_description``, a
    :func:`scene_dict` of ``light_groups``) → the index of its group in ``light_groups``:
    a lamp's from the lamp, every other one (the sky, a moon) the pass's sky group."""
    index = {g: i for i, g in enumerate(light_groups)}
    groups = {}
    for lamp in parts.lamps:
        obj = scene_description.get(f"lamp_{lamp.name}")
        if lamp.light_group in index and obj is not None:
            groups[obj.emitter() if lamp.shape is not None else obj] = index[lamp.light_group]
    sky = [g for g in light_groups if g in SKY_GROUPS]
    for emitter in loaded_scene.emitters():
        if emitter not in groups:
            if not sky:
                raise ValueError("an emitter that is neither a lamp nor a sky")
            groups[emitter] = index[sky[0]]
    return groups
