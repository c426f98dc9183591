"""Geometry helpers of the interpreter: polygons, prisms, primitives, roofs. No language code here."""
