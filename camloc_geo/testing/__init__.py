"""Generators of synthetic test and benchmark data (scenes, videos, traces).

Not part of the engine: nothing in the core imports this subpackage.
"""
