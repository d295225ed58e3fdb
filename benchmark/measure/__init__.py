"""Measurement of a camera: test targets and the ISO 12233 slanted-edge MTF."""
