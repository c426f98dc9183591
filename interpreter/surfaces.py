"""CGA's material attributes beyond colour and textures: opacity, metallic, roughness, the
specular colour, shininess and reflectivity.

``set(material.opacity, 0.4)`` (and the others: ``material.metallic``, ``material.roughness``,
``material.specular.r``/``.g``/``.b``, ``material.shininess``, ``material.reflectivity``)
changes the shape's material as CGA's material attributes do, for the shape and what it
derives.  The shape's ``material`` (and the terminal list's column of that name) then holds a
:class:`Surface`, the material's name with those values, instead of the bare name; a shape
that sets none keeps a plain name (or None), so grammars that never set them write the files
they always did.  The writers read the values back with :func:`name_of` and :func:`values_of`:
glTF's ``baseColorFactor`` alpha (``alphaMode`` BLEND below 1), ``metallicFactor``,
``roughnessFactor``, KHR_materials_specular's ``specularColorFactor`` and, as glTF has no
word for them, shininess and reflectivity in the material's ``extras``; OBJ's ``d``, ``Pm``,
``Pr``, ``Ks`` and ``Ns`` (MTL has no reflectivity).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

# the attributes after ``material.``, in the order of values_of()
ATTRIBUTES = (
    "opacity",
    "metallic",
    "roughness",
    "specular.r",
    "specular.g",
    "specular.b",
    "shininess",
    "reflectivity",
)
# what a material without them is (glTF's roughness in bgr's files; CGA's other defaults)
DEFAULTS = (1.0, 0.0, 0.8, 0.0, 0.0, 0.0, 0.0, 0.0)
BASIC = 3  # opacity, metallic and roughness: always written once one of the values is set
LARGEST = {"shininess": 128.0}  # a Phong exponent; the others are 0..1


@dataclass(frozen=True, slots=True)
class Surface:
    name: str | None
    opacity: float = DEFAULTS[0]
    metallic: float = DEFAULTS[1]
    roughness: float = DEFAULTS[2]
    specular_r: float = DEFAULTS[3]
    specular_g: float = DEFAULTS[4]
    specular_b: float = DEFAULTS[5]
    shininess: float = DEFAULTS[6]
    reflectivity: float = DEFAULTS[7]


def name_of(material) -> str | None:
    """The material's name: a plain name, or a Surface's."""
    return material.name if isinstance(material, Surface) else material


def values_of(material) -> tuple[float, ...]:
    """The values of ATTRIBUTES of a material; the defaults for a plain name."""
    if isinstance(material, Surface):
        return tuple(getattr(material, _field(a)) for a in ATTRIBUTES)
    return DEFAULTS


def set_values(values: tuple[float, ...]) -> dict[str, float]:
    """The values a file shows: opacity, metallic and roughness, and the others that differ
    from their defaults."""
    return {
        a: v
        for i, (a, v) in enumerate(zip(ATTRIBUTES, values, strict=True))
        if i < BASIC or v != DEFAULTS[i]
    }


def renamed(material, name: str):
    """material(name) on a shape: the name changes, the values set on it stay."""
    return replace(material, name=name) if isinstance(material, Surface) else name


def with_value(material, attribute: str, value: float) -> Surface:
    """set(material.<attribute>, value): the material with that value."""
    surface = material if isinstance(material, Surface) else Surface(material)
    return replace(surface, **{_field(attribute): value})


def _field(attribute: str) -> str:
    return attribute.replace(".", "_")
