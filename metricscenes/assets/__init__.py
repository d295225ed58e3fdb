"""Procedural, seeded asset library: cars, roads, vegetation, street lights, skies.

Every asset is built from numpy geometry and spectral tables; nothing is downloaded.
"""
