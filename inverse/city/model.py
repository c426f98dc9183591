"""What the city readers hand to de-instancing: objects of triangles in bgr's frame.

bgr's frame is glTF's: y up, metres.  Inputs that are z up (CityJSON, CityGML, most OBJ exports
of GIS data) are turned so that input (x, y, z) = (east, north, up) becomes bgr
(x, y, z) = (east, up, -north), the same convention as GeoJSON lots (interpreter/lots.py).
Large projected coordinates are re-centred on ``offset`` (in the input's own frame), which
:meth:`CityScene.to_input` adds back, so that outputs can land in the input's frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class CityObject:
    """One object of the input: a building (to proceduralize) or anything else (carried)."""

    name: str  # the object's id, OBJ object/group name, or "object-N" for connected components
    kind: str  # "Building", "BuildingPart", another CityJSON type, or "object" for mesh formats
    vertices: np.ndarray  # (V, 3) float64 in bgr's frame (y up), re-centred
    faces: np.ndarray  # (F, 3) int64 into vertices, counter-clockwise seen from outside
    colors: np.ndarray | None = None  # (F, 4) uint8 per face, where the input has colours
    proceduralize: bool = True  # False: carried through as it is (roads, water, terrain...)
    attributes: dict = field(default_factory=dict)


@dataclass
class CityScene:
    """Everything read from one input file."""

    objects: list[CityObject]
    source: str  # the path as the user gave it
    up: str  # "y" or "z": the input's up axis
    offset: np.ndarray = field(default_factory=lambda: np.zeros(3))  # input frame, subtracted
    crs: str | None = None  # the CRS the input names, if any

    def to_input(self, points: np.ndarray) -> np.ndarray:
        """Points of bgr's frame back in the input's frame (its axes, its offset)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if self.up == "z":
            p = np.column_stack([p[:, 0], -p[:, 2], p[:, 1]])
        return p + self.offset

    def from_input(self, points: np.ndarray) -> np.ndarray:
        """Points of the input's frame in bgr's frame (the inverse of :meth:`to_input`)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3) - self.offset
        if self.up == "z":
            p = np.column_stack([p[:, 0], p[:, 2], -p[:, 1]])
        return p

    @property
    def triangles(self) -> int:
        return sum(len(o.faces) for o in self.objects)
