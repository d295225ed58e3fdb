"""Body-style table of the procedural car library: dimension ranges and profile shapes.

Dimension ranges follow current European market cars of each class (manufacturer data sheets,
e.g. VW Golf/Polo, Toyota Corolla, BMW 3 Series touring, Audi A5 coupe, VW Tiguan/Toyota
RAV4, Ford Ranger/Toyota Hilux double cab, VW Transporter/Mercedes Vito): length 3.7-5.45 m,
width 1.66-2.02 m (without mirrors), height 1.30-1.98 m.

Profiles are control points (u, z/height) with u = 0 at the rear tip and 1 at the front tip;
``greenhouse`` = (rear-window base, roof rear, roof front, windshield base) in u.
"""

from __future__ import annotations

STYLE_SCHEDULE = (
    "sedan", "hatchback", "suv", "sedan", "wagon", "hatchback", "coupe", "suv", "pickup", "van",
)
"""Style of car_id by ``car_id % 10``: sedans, hatchbacks and SUVs twice as common."""

STYLES: dict[str, dict] = {
    "sedan": dict(
        length=(4.40, 4.95), width=(1.75, 1.86), height=(1.40, 1.49), wheelbase=(2.65, 2.90),
        tyre_radius=(0.31, 0.335), tyre_width=(0.205, 0.235), front_overhang_frac=0.46,
        top=((0, 0.47), (0.02, 0.60), (0.06, 0.665), (0.22, 0.68), (0.5, 0.665), (0.74, 0.655),
             (0.9, 0.585), (0.97, 0.53), (1.0, 0.44)),
        bot=((0, 0.25), (0.06, 0.20), (0.16, 0.12), (0.5, 0.11), (0.84, 0.12), (0.93, 0.19), (1.0, 0.23)),
        greenhouse=(0.19, 0.35, 0.61, 0.76), tumblehome=0.72,
    ),
    "hatchback": dict(
        length=(3.70, 4.35), width=(1.66, 1.80), height=(1.42, 1.52), wheelbase=(2.40, 2.65),
        tyre_radius=(0.30, 0.325), tyre_width=(0.185, 0.225), front_overhang_frac=0.55,
        top=((0, 0.45), (0.015, 0.58), (0.04, 0.635), (0.5, 0.64), (0.72, 0.635), (0.9, 0.575),
             (0.97, 0.52), (1.0, 0.43)),
        bot=((0, 0.24), (0.06, 0.19), (0.16, 0.115), (0.5, 0.105), (0.84, 0.115), (0.93, 0.18), (1.0, 0.22)),
        greenhouse=(0.035, 0.15, 0.59, 0.745), tumblehome=0.74,
    ),
    "wagon": dict(
        length=(4.55, 4.95), width=(1.78, 1.86), height=(1.45, 1.52), wheelbase=(2.70, 2.90),
        tyre_radius=(0.315, 0.335), tyre_width=(0.205, 0.235), front_overhang_frac=0.45,
        top=((0, 0.45), (0.015, 0.59), (0.04, 0.645), (0.5, 0.65), (0.74, 0.645), (0.9, 0.575),
             (0.97, 0.52), (1.0, 0.43)),
        bot=((0, 0.24), (0.06, 0.19), (0.16, 0.115), (0.5, 0.105), (0.84, 0.115), (0.93, 0.18), (1.0, 0.22)),
        greenhouse=(0.025, 0.075, 0.61, 0.76), tumblehome=0.75,
    ),
    "coupe": dict(
        length=(4.20, 4.70), width=(1.78, 1.88), height=(1.30, 1.38), wheelbase=(2.55, 2.75),
        tyre_radius=(0.315, 0.34), tyre_width=(0.225, 0.255), front_overhang_frac=0.47,
        top=((0, 0.50), (0.02, 0.63), (0.07, 0.69), (0.18, 0.70), (0.5, 0.675), (0.72, 0.655),
             (0.9, 0.575), (0.97, 0.51), (1.0, 0.42)),
        bot=((0, 0.25), (0.06, 0.20), (0.16, 0.115), (0.5, 0.105), (0.84, 0.115), (0.93, 0.19), (1.0, 0.23)),
        greenhouse=(0.14, 0.40, 0.585, 0.735), tumblehome=0.70,
    ),
    "suv": dict(
        length=(4.30, 4.95), width=(1.80, 1.98), height=(1.62, 1.80), wheelbase=(2.60, 2.95),
        tyre_radius=(0.345, 0.38), tyre_width=(0.215, 0.255), front_overhang_frac=0.50,
        top=((0, 0.46), (0.015, 0.565), (0.045, 0.60), (0.5, 0.605), (0.75, 0.60), (0.92, 0.565),
             (0.98, 0.52), (1.0, 0.45)),
        bot=((0, 0.22), (0.06, 0.18), (0.16, 0.125), (0.5, 0.12), (0.84, 0.125), (0.93, 0.18), (1.0, 0.21)),
        greenhouse=(0.03, 0.085, 0.62, 0.765), tumblehome=0.78,
    ),
    "pickup": dict(
        length=(5.00, 5.45), width=(1.85, 2.02), height=(1.78, 1.92), wheelbase=(3.00, 3.35),
        tyre_radius=(0.37, 0.40), tyre_width=(0.245, 0.275), front_overhang_frac=0.45,
        top=((0, 0.50), (0.012, 0.605), (0.03, 0.62), (0.42, 0.625), (0.47, 0.60), (0.77, 0.60),
             (0.93, 0.57), (0.985, 0.53), (1.0, 0.47)),
        bot=((0, 0.25), (0.05, 0.20), (0.14, 0.14), (0.5, 0.13), (0.86, 0.14), (0.94, 0.19), (1.0, 0.23)),
        greenhouse=(0.445, 0.465, 0.645, 0.775), tumblehome=0.80, bed=(0.025, 0.425),
    ),
    "van": dict(
        length=(4.70, 5.40), width=(1.88, 2.02), height=(1.86, 1.98), wheelbase=(2.95, 3.40),
        tyre_radius=(0.33, 0.35), tyre_width=(0.205, 0.235), front_overhang_frac=0.55,
        top=((0, 0.44), (0.012, 0.515), (0.035, 0.53), (0.5, 0.53), (0.82, 0.53), (0.9, 0.50),
             (0.965, 0.44), (1.0, 0.35)),
        bot=((0, 0.19), (0.05, 0.16), (0.14, 0.10), (0.5, 0.095), (0.86, 0.10), (0.94, 0.15), (1.0, 0.18)),
        greenhouse=(0.012, 0.035, 0.80, 0.90), tumblehome=0.86,
    ),
}
"""Per-style ranges (m) and shape tables."""

# Paint popularity, global 2022 (Axalta Global Automotive Color Popularity Report 2022):
# white 35 %, black 19 %, grey 17 %, silver 9 %, blue 7 %, red 7 %, others 6 %.
PAINT_WEIGHTS: dict[str, float] = {
    "white": 0.30, "black": 0.17, "grey": 0.14, "silver": 0.10, "blue": 0.07, "red": 0.07,
    "dark_blue": 0.04, "dark_red": 0.025, "green": 0.02, "beige": 0.02, "gold": 0.01,
    "yellow": 0.01, "orange": 0.01, "brown": 0.015,
}
