"""Whether a planned scene holds where the car stands: geometry only, before anything renders.

A car far down the road must still stand on paved road (inside the paved width, before the
detailed road's end), below the camera's horizontal (so that it is seen against the ground,
not the sky, and its contact with the road is in view), inside the reference field, and
large enough on the reference grid for its box to be more than a pixel. The farthest distance
is the binding case for all four; :func:`farthest_scene_problems` checks it for every
environment of a manifest, and ``generate`` refuses a manifest that fails (docs/scenes.md,
"Distances beyond 200 m").

Ground truth keeps every box however small: COCO's area ranges are not applied. A box the
detector cannot see is the miss that OD50 measures.
"""

from __future__ import annotations

import numpy as np

from metricscenes.assets import roads
from metricscenes.geometry import TanExtent, extent_within
from metricscenes.groundtruth import car_box_tan
from metricscenes.manifest import Manifest
from metricscenes.plan import ScenePlan, plan_collection

# A box must span at least this many reference-grid pixels each way: below it the box is a
# point, not a car (the reference grid is what ground truth is written on).
MIN_BOX_REFERENCE_PX = 1.0
# How far below the car's wheels the camera's horizontal must lie, in reference-grid pixels.
MIN_BELOW_HORIZON_PX = 1.0


def scene_problems(manifest: Manifest, scene: ScenePlan) -> list[str]:
    """What does not hold for ``scene`` (one line each, naming it), or []."""
    from metricscenes import scene as scene_mod

    env = scene.environment
    road = roads.road_spec(env.road_id)
    pose = scene_mod.car_pose(env, scene.distance_m)
    vertices = scene_mod.car_vertices(env, pose)
    grid = manifest.reference_grid
    pitch_x, pitch_y = grid.field.width / grid.width_px, grid.field.height / grid.height_px
    road_end = manifest.detailed_road_end_m
    where = f"{scene.scene_id} (car {env.car_id}, road {env.road_id}, {scene.distance_m:g} m)"
    problems = []
    ground = vertices[vertices[:, 2] <= vertices[:, 2].min() + 0.05]  # the car's lowest points: its tyres
    off_centre = float(np.abs(ground[:, 1] - roads.centre_line_y_m(road)).max())
    if off_centre > road.half_paved_m or ground[:, 0].max() > road_end:
        problems.append(f"{where}: the car's wheels leave the paved road (|y - centre| up to "
                        f"{off_centre:.2f} m of {road.half_paved_m:.2f} m, x up to "
                        f"{ground[:, 0].max():.1f} m of {road_end:g} m)")
    x0, y0, x1, y1 = car_box_tan(vertices)
    if not extent_within(TanExtent(x0, y0, x1, y1), grid.field):
        problems.append(f"{where}: the car's box leaves the reference field")
    if y1 < MIN_BELOW_HORIZON_PX * pitch_y:
        problems.append(f"{where}: the car's wheels are {y1 / pitch_y:.2f} reference pixels below the horizontal "
                        f"(at least {MIN_BELOW_HORIZON_PX:g}): it is not seen standing on the road")
    width_px, height_px = (x1 - x0) / pitch_x, (y1 - y0) / pitch_y
    if min(width_px, height_px) < MIN_BOX_REFERENCE_PX:
        problems.append(f"{where}: the car's box is {width_px:.2f} x {height_px:.2f} reference pixels (at least "
                        f"{MIN_BOX_REFERENCE_PX:g} each way): use a finer reference_grid or nearer distances")
    return problems


def farthest_scene_problems(manifest: Manifest) -> list[str]:
    """:func:`scene_problems` of every environment's scene at the manifest's farthest distance."""
    farthest = max(manifest.distances_m)
    return [problem for scene in plan_collection(manifest) if scene.distance_m == farthest
            for problem in scene_problems(manifest, scene)]
