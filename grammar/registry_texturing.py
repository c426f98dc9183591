"""The texturing operations of the registry, as CGA's: projections, texture and normal maps,
and the uv edits (``setupProjection``, ``projectUV``, ``texture``, ``tileUV`` ...).
:mod:`registry` gathers them into ``OPERATIONS`` in the order given here.
"""

from __future__ import annotations

from .registry_kinds import (
    NORMALIZE_MODE,
    NORMALIZE_TYPE,
    NUMBER,
    PROJECTION_AXES,
    STRING,
    TEX_SIZE,
    Op,
    Param,
    _sig,
)

TEXTURING: list[Op] = [
    # -- texturing (CGA's texturing operations; docs/language.md "Textures") -------------
    Op(
        "setupProjection",
        "texturing",
        _sig(
            Param("uvSet", NUMBER),
            Param("axes", PROJECTION_AXES),
            Param("w", TEX_SIZE),
            Param("h", TEX_SIZE),
            Param("uOffset", NUMBER, 0.0),
            Param("vOffset", NUMBER, 0.0),
            Param("uwFactor", NUMBER, 0.0),
        ),
        "Set up the texture projection of uv-set 0..9 on the scope (`scope.xy`, `scope.xz`, "
        "...) or the world (`world.xy`, ...) axes: a tile `w` by `h` metres (`~w` about w so "
        "that whole tiles span the scope, `'f` a fraction of it, negative mirrors), offsets "
        "in metres, `uwFactor` how much the third axis adds to u. The projection stays where "
        "it was set up: split pieces, faces and moved shapes keep it, so tiles line up across "
        "every cut.",
        "setupProjection(0, scope.xy, ~1.5, 1)",
    ),
    Op(
        "projectUV",
        "texturing",
        _sig(Param("uvSet", NUMBER)),
        "Give the shape the texture coordinates of uv-set `uvSet` from its projection.",
        "projectUV(0)",
    ),
    Op(
        "texture",
        "texturing",
        _sig(Param("path", STRING)),
        "Set the colour map (uv-set 0): a PNG or JPEG file, found like assets (the grammar's "
        "folder, the stdlib, --allow-path); its alpha channel is the opacity. "
        '`texture("")` removes it, so that an inserted asset shows its own texture.',
        'texture("bricks.png")',
    ),
    Op(
        "normalMap",
        "texturing",
        _sig(Param("path", STRING)),
        "Set the normal map (CGA's material.normalmap, uv-set 5): a PNG or JPEG file, found "
        "like texture().",
        'normalMap("bricks_normal.png")',
    ),
    Op(
        "tileUV",
        "texturing",
        _sig(Param("uvSet", NUMBER), Param("w", TEX_SIZE), Param("h", TEX_SIZE)),
        "Rescale the texture coordinates so that one tile is `w` by `h` metres (`~w`, `'f` "
        "and negative as in setupProjection; 0 leaves that direction as it is).",
        "tileUV(0, ~2, '0.5)",
    ),
    Op(
        "scaleUV",
        "texturing",
        _sig(Param("uvSet", NUMBER), Param("u", NUMBER), Param("v", NUMBER)),
        "Multiply the texture coordinates by `u` and `v`.",
        "scaleUV(0, 2, 2)",
    ),
    Op(
        "translateUV",
        "texturing",
        _sig(Param("uvSet", NUMBER), Param("u", NUMBER), Param("v", NUMBER)),
        "Add `u` and `v` to the texture coordinates (0.5 moves the texture half a tile).",
        "translateUV(0, 0.5, 0)",
    ),
    Op(
        "rotateUV",
        "texturing",
        _sig(Param("uvSet", NUMBER), Param("angle", NUMBER)),
        "Rotate the texture coordinates about u = v = 0 by `angle` degrees (counter-clockwise).",
        "rotateUV(0, 90)",
    ),
    Op(
        "normalizeUV",
        "texturing",
        _sig(
            Param("uvSet", NUMBER),
            Param("mode", NORMALIZE_MODE),
            Param("type", NORMALIZE_TYPE, "collectiveAllFaces"),
        ),
        "Map the texture coordinates of the shape's scope onto 0..1: `uv` both, `u` or `v` "
        "one, `uvUniform` both by one factor.",
        "normalizeUV(0, uv, collectiveAllFaces)",
    ),
    Op(
        "deleteUV",
        "texturing",
        _sig(Param("uvSet", NUMBER)),
        "Remove the texture coordinates of uv-set `uvSet` (its projection stays).",
        "deleteUV(0)",
    ),
]
