"""Geometry helpers of the interpreter: polygons, prisms, primitives, roofs; no language code."""
