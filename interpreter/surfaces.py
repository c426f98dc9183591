"""CGA's material attributes beyond colour and textures: opacity, metallic and roughness.

``set(material.opacity, 0.4)`` (and ``material.metallic``, ``material.roughness``) changes the
shape's material as CGA's material attributes do, for the shape and what it derives.  The shape's
``material`` (and the terminal list's column of that name) then holds a :class:`Surface`, the
material's name with those values, instead of the bare name; a shape that sets none keeps a
plain name (or None), so grammars that never set them write the files they always did.  The
writers read the values back with :func:`name_of` and :func:`values_of`: glTF's
``baseColorFactor`` alpha (``alphaMode`` BLEND below 1), ``metallicFactor`` and
``roughnessFactor``; OBJ's ``d``, ``Pm`` and ``Pr``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

ATTRIBUTES = ("opacity", "metallic", "roughness")
DEFAULTS = (1.0, 0.0, 0.8)  # what a material without them is (glTF's roughness in bgr's files)


@dataclass(frozen=True, slots=True)
class Surface:
    name: str | None
    opacity: float = DEFAULTS[0]
    metallic: float = DEFAULTS[1]
    roughness: float = DEFAULTS[2]


def name_of(material) -> str | None:
    """The material's name: a plain name, or a Surface's."""
    return material.name if isinstance(material, Surface) else material


def values_of(material) -> tuple[float, float, float]:
    """(opacity, metallic, roughness) of a material; the defaults for a plain name."""
    if isinstance(material, Surface):
        return (material.opacity, material.metallic, material.roughness)
    return DEFAULTS


def renamed(material, name: str):
    """material(name) on a shape: the name changes, the values set on it stay."""
    return replace(material, name=name) if isinstance(material, Surface) else name


def with_value(material, attribute: str, value: float) -> Surface:
    """set(material.<attribute>, value): the material with that value."""
    surface = material if isinstance(material, Surface) else Surface(material)
    return replace(surface, **{attribute: value})
