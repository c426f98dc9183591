"""One function per operation, grouped by family; IMPLEMENTATIONS maps registry names to them.

Every function has the signature ``op(app, shape, step, args) -> consumed``: ``app`` is the rule
application (for evaluating, spawning pieces and reporting errors), ``shape`` the current shape
(changed in place), ``step`` the syntax node, ``args`` the evaluated arguments followed by the
scope ``center()`` aligns to.  It returns True when the shape is used up (split, comp, roof...).
"""

from . import (
    appearance,
    attributes,
    components,
    envelope,
    inserts,
    parts,
    reporting,
    roofs,
    scopes,
    setbacks,
    splits,
    texturing,
    transforms,
    trims,
)

IMPLEMENTATIONS = {
    "t": transforms.translate,
    "r": transforms.rotate,
    "s": transforms.scale,
    "center": transforms.center,
    "matrix": transforms.matrix,
    "reverseNormals": transforms.reverse_normals,
    "rotateScope": scopes.rotate_scope,
    "alignScopeToAxes": scopes.align_scope_to_axes,
    "alignScopeToGeometry": scopes.align_scope_to_geometry,
    "mirror": scopes.mirror,
    "cleanupGeometry": scopes.cleanup_geometry,
    "convexify": scopes.convexify,
    "split": splits.split,
    "comp": parts.comp,
    "offset": components.offset,
    "setback": setbacks.setback,
    "innerRectangle": setbacks.inner_rectangle,
    "extrude": components.extrude,
    "envelope": envelope.envelope,
    "footprint": components.footprint,
    "polygon": components.polygon,
    "taper": components.taper,
    "roof": roofs.roof,
    "i": inserts.insert,
    "trim": trims.trim,
    "color": appearance.color,
    "material": appearance.material,
    "label": appearance.label,
    "report": reporting.report,
    "print": reporting.print_value,
    "set": attributes.set_attr,
    "setupProjection": texturing.setup_projection,
    "projectUV": texturing.project_uv,
    "texture": texturing.texture,
    "normalMap": texturing.normal_map,
    "tileUV": texturing.tile_uv,
    "scaleUV": texturing.scale_uv,
    "translateUV": texturing.translate_uv,
    "rotateUV": texturing.rotate_uv,
    "normalizeUV": texturing.normalize_uv,
    "deleteUV": texturing.delete_uv,
}
