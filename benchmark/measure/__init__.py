"""Measurement of a camera: test targets, the ISO 12233 slanted-edge MTF, the photon transfer
and the figures a spec implies (``benchmark cameras show``)."""
