"""What a collection gives a camera, as runs record it and cache keys hash it: how its layers
are composited, the field it covers, the camera's window in it, and a read-time condition's
definition. Here, below both the run and the keys, so that neither reaches into the other."""

from __future__ import annotations

# How the collection's layers are composited for a camera (metricscenes.store.Collection.radiance):
# "car" since v0.1.0a5 (CHANGELOG.md), the inset at its own resolution only around the car. Runs made
# before it recorded none, so a sweep does not take them for this composite's.
COMPOSITE = "car"


def collection_field(collection):
    """The field (tangent extent) a collection's plates and ground-truth grid cover
    (``Collection.field``), or the reference field for an object that cannot say (a
    test double)."""
    from metricscenes.geometry import REFERENCE_EXTENT

    return getattr(collection, "field", REFERENCE_EXTENT)


def collection_widest_field(collection):
    """The widest field a camera may see in a collection: its wide plate's
    (``Collection.widest_field``), or None where it has none (or cannot say: a test double)."""
    return getattr(collection, "widest_field", None)


def camera_geometry(collection, camera) -> dict | None:
    """Where the camera sees less than the collection's field: its field and window, as
    recorded in results.json (``camera_geometry``) and in the sweep cache key; None for a
    camera that sees the whole field (the 13 registry cameras), whose results keep their
    bytes. :class:`benchmark.camera.pipeline.FieldOfViewError` for a camera that sees more."""
    from benchmark.camera.pipeline import camera_window

    field = collection_field(collection)
    return geometry_record(camera, field, camera_window(camera, field, collection_widest_field(collection)))


def geometry_record(camera, field, window) -> dict | None:
    """:func:`camera_geometry` of a camera whose window of ``field`` is known."""
    from metricscenes.geometry import fov_deg

    if window == field:
        return None
    return {"hfov_deg": round(camera.hfov_deg, 6), "vfov_deg": round(camera.vfov_deg, 6),
            "window_tan": list(window.as_tuple()), "collection_fov_deg": [round(v, 6) for v in fov_deg(field)]}


def condition_spec(collection, condition: str) -> dict | None:
    """A read-time condition's definition (``Collection.read_time_condition``), None for any
    other (or for a collection that cannot say: a test double)."""
    read = getattr(collection, "read_time_condition", None)
    return None if read is None else read(condition)
