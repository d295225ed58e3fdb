"""The camera's own vehicle: its head lamps (light groups 'ego_lights' and 'ego_high_beam').

The camera sits behind the windscreen at (0, 0, 1.5 m) (DESIGN §2); the vehicle's front is
about 2 m ahead of it. Its two head lamps stand 0.70 m above the road (UN ECE R48 §6.2.4:
dipped-beam lamps 500-1200 mm high; 0.6-0.8 m on passenger cars) and 1.40 m apart (ECE
R48: inner edges >= 600 mm apart, outer edges <= 400 mm from the vehicle's side), aimed
straight ahead. The lamps themselves are behind the camera's field of view and are not
modelled as shapes: only their light (goniometric spots, :mod:`metricscenes.assets.beams`)
enters the scene. The low beam is group 'ego_lights'; the optional high beam
'ego_high_beam' (on top of the low beam when both groups are weighted 1).
"""

from __future__ import annotations

from metricscenes.assets import beams
from metricscenes.assets.parts import Lamp, SceneParts
from metricscenes.geometry import CAMERA_HEIGHT_M

CAMERA_POSITION_M = (0.0, 0.0, CAMERA_HEIGHT_M)
"""Where the camera sits (world m): the origin of every scene, 1.5 m above the road."""

LAMP_AHEAD_OF_CAMERA_M = 2.0
LAMP_HEIGHT_M = 0.70
LAMP_SEPARATION_M = 1.40
LAMP_SPECTRUM = "led_5700k"
"""CIE LED-B4 (5109 K): phosphor-white LED head lamps, as most new cars."""

GROUPS = {"ego_lights": "low", "ego_high_beam": "high"}


def lamp_positions_m() -> list[tuple[float, float, float]]:
    """World positions (m) of the left and right head lamp."""
    half = LAMP_SEPARATION_M / 2
    return [(LAMP_AHEAD_OF_CAMERA_M, side * half, LAMP_HEIGHT_M) for side in (1.0, -1.0)]


def ego_lamp_parts() -> SceneParts:
    """The ego vehicle's low and high beams as spot lamps (no shapes)."""
    lamps = []
    for group, beam in GROUPS.items():
        for side, origin in zip(("left", "right"), lamp_positions_m()):
            spot = beams.head_lamp_spot(beam, LAMP_SPECTRUM, origin, (1.0, 0.0, 0.0))
            lamps.append(Lamp(f"ego_{beam}_beam_{side}", group, None, spot))
    return SceneParts(lamps=tuple(lamps))
