"""The rules every part of a camera spec follows: frozen, no unknown keys
(:class:`SpecModel`), one serialisation rule for fields added later (:func:`added_later`:
left out of the JSON, hence of the sha256, at their default), and the plausible ranges of
fields whose unit is easy to get wrong (:data:`PLAUSIBLE`: :func:`check_plausible` refuses
what no sensor has, :func:`plausibility_warnings` names what is possible but unusual).

Kept apart from :mod:`benchmark.camera.spec` so that the specs of each stage
(:mod:`~benchmark.camera.spec_optics`, :mod:`~benchmark.camera.spec_sensor` and its HDR readout
:mod:`~benchmark.camera.spec_readout`, :mod:`~benchmark.camera.spec_exposure`,
:mod:`~benchmark.camera.spec_isp`) can follow them without importing the whole camera spec
(docs/camera.md, "Adding a camera feature", "Plausible values").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pydantic import BaseModel, ConfigDict, Field, model_serializer

_STRICT = ConfigDict(extra="forbid", frozen=True)


@dataclass(frozen=True)
class Plausible:
    """Where one spec field's values lie on real sensors (docs/camera.md, "Plausible values").

    A value outside ``refused`` is no sensor's: it is refused with the unit mistake it most
    likely is (the first of ``mistakes``, ``(unit, factor to this field's unit)``, that
    brings it inside). A value outside ``usual`` but inside ``refused`` is possible, and
    ``benchmark cameras show`` warns about it."""

    what: str
    unit: str
    refused: tuple[float, float]
    usual: tuple[float, float]
    mistakes_below: tuple[tuple[str, float], ...] = ()
    mistakes_above: tuple[tuple[str, float], ...] = ()


PLAUSIBLE: dict[str, Plausible] = {
    "exposure.max_exposure_s": Plausible("an exposure cap", "s", (1e-7, 1.0), (1e-4, 0.1),
                                         mistakes_above=(("ms", 1e-3), ("us", 1e-6))),
    "exposure.exposure_s": Plausible("an exposure time", "s", (1e-7, 1.0), (1e-5, 0.1),
                                     mistakes_above=(("ms", 1e-3), ("us", 1e-6))),
    "sensor.conversion_gain_uv_per_e": Plausible("a conversion gain", "uV/e-", (1.0, 1000.0), (10.0, 300.0),
                                                 mistakes_below=(("V/e-", 1e6), ("mV/e-", 1e3)),
                                                 mistakes_above=(("nV/e-", 1e-3),)),
    "sensor.well_capacity_e": Plausible("a full well", "e-", (300.0, 1e7), (2000.0, 1e6),
                                        mistakes_below=(("ke-", 1e3),)),
    "sensor.voltage_swing_v": Plausible("a pixel voltage swing", "V", (0.05, 5.0), (0.2, 3.3),
                                        mistakes_above=(("mV", 1e-3),)),
    "sensor.read_noise_e": Plausible("a read noise", "e-", (0.0, 1000.0), (0.0, 50.0)),
    "sensor.dark_current_e_per_s": Plausible("a dark current", "e-/s", (0.0, 1e6), (0.0, 1000.0)),
    "sensor.dsnu_v": Plausible("a DSNU", "V", (0.0, 0.1), (0.0, 0.01), mistakes_above=(("mV", 1e-3),)),
    "sensor.prnu_fraction": Plausible("a PRNU", "(fraction)", (0.0, 0.1), (0.0, 0.03),
                                      mistakes_above=(("percent", 1e-2),)),
}
"""Plausible ranges of the spec fields whose unit is easy to get wrong (sources in docs/camera.md)."""


def _unit(unit: str) -> str:
    return "" if unit.startswith("(") else f" {unit}"


def _number(value: float) -> str:
    """``10000000``, ``0.03``, ``1e-06``: as short as exact, without ``1e+07``."""
    return f"{value:.0f}" if abs(value) >= 1e5 and float(value).is_integer() else f"{value:.6g}"


def check_plausible(field: str, value):
    """``value`` of ``field`` (``"sensor.well_capacity_e"``) if a sensor can have it; else a
    one-line ValueError with the plausible range and the likely unit mistake. Not a number:
    returned as it is, for pydantic's own check."""
    rule = PLAUSIBLE[field]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return value
    lo, hi = rule.refused
    if lo <= value <= hi:
        return value
    mistakes = rule.mistakes_below if value < lo else rule.mistakes_above
    hint = next((f"; if it was meant in {unit}, write {_number(value * factor)}" for unit, factor in mistakes
                 if lo <= value * factor <= hi), "")
    side = "below" if value < lo else "above"
    raise ValueError(f"{rule.what} of {_number(value)}{_unit(rule.unit)} is {side} the plausible range "
                     f"{_number(lo)} to {_number(hi)}{_unit(rule.unit)} of real sensors{hint} "
                     "(docs/camera.md, \"Plausible values\")")


def plausibility_warnings(camera) -> list[str]:
    """One line per field of ``camera`` (a :class:`~benchmark.camera.spec.CameraSpec`) whose
    value is possible but unusual (outside ``usual``)."""
    out = []
    for field, rule in PLAUSIBLE.items():
        section, name = field.split(".")
        value = getattr(getattr(camera, section), name)
        lo, hi = rule.usual
        if not lo <= value <= hi:
            out.append(f"{field} {_number(value)}{_unit(rule.unit)} is unusual (most sensors: {_number(lo)} to "
                       f"{_number(hi)}{_unit(rule.unit)}): check its unit")
    return out


ADDED_LATER = "added_later"
"""Marks (in ``json_schema_extra``) a field declared with :func:`added_later`."""


def added_later(default, **constraints):
    """A spec field added after the registry and its leaderboard (a ``Field`` with
    ``default`` and its ``constraints``): :class:`SpecModel` writes it only where it is
    not at its default, so every spec written before it keeps its canonical JSON, hence
    its sha256 (docs/camera.md, "Adding a camera feature")."""
    return Field(default, json_schema_extra={ADDED_LATER: True}, **constraints)


class SpecModel(BaseModel):
    """A part of a camera spec (frozen, no unknown keys), serialised by the one rule for
    specs that grow: a field declared with :func:`added_later` is left out wherever it
    is at its default."""

    model_config = _STRICT

    @model_serializer(mode="wrap")
    def _omit_later_fields_at_default(self, handler):
        data = handler(self)
        if isinstance(data, dict):
            for name, field in type(self).model_fields.items():
                extra = field.json_schema_extra
                if isinstance(extra, dict) and extra.get(ADDED_LATER) and getattr(self, name) == field.default:
                    data.pop(name, None)
        return data
