"""Which subtrees of a terminal list's rule tree are faces, read from the planes they lie in.

A subtree is one face when its terminals lie in one plane (within :data:`DEPTH`, so that a
recess or a frame belongs to its wall), or when all but minor parts at other angles do (the
reveal of a window); :func:`_face_nodes` collects those subtrees, gathering the children of a
rule that are the pieces of a face with no rule of its own.
"""

from __future__ import annotations

from .terminal_list import _dot, _Node, _Terminal


def _same_axes(a, b) -> bool:
    return all(abs(a[i][j] - b[i][j]) < 1e-6 for i in range(3) for j in range(3))


DEPTH = 1.0  # metres: recessed glass and extruded frames within this of the wall belong to its face


def _same_plane(t: _Terminal, ref: _Terminal) -> bool:
    """Whether ``t`` lies in ``ref``'s face, within DEPTH of its plane (a recess or a frame is
    projected onto the face; its depth is not part of the schema).

    Two flat terminals (or two solids) must have the same axes and be flat along the same one.
    A solid beside a flat terminal only needs one of its axes along the face's normal, whichever
    it is: a frame extruded from a wall has its depth along z or along y depending on how
    extrude() sets the scope, and it belongs to the wall either way."""
    if t.flat == ref.flat:
        if t.k != ref.k or not _same_axes(t.axes, ref.axes):
            return False
        normal = ref.normal
    else:
        normal = (ref if ref.flat else t).normal
        solid = t if ref.flat else ref
        if not any(abs(abs(_dot(a, normal)) - 1.0) < 1e-6 for a in solid.axes):
            return False
    return abs(_dot(t.origin, normal) - _dot(ref.origin, normal)) < DEPTH


def _reference(terminals: list[_Terminal]) -> _Terminal:
    """The terminal whose plane a group of terminals is read in: the first flat one (a face's
    own surface), else the first."""
    return next((t for t in terminals if t.flat), terminals[0])


def _coplanar(terminals: list[_Terminal]) -> bool:
    """One face: every terminal in the reference's plane."""
    ref = _reference(terminals)
    return all(_same_plane(t, ref) for t in terminals)


def _area(t: _Terminal) -> float:
    p, q = t.plane
    return t.size[p] * t.size[q]


MINOR = 0.35  # parts off the main plane (reveals, sill tops) up to this share of its area


def _main_plane(terminals: list[_Terminal]) -> set[int] | None:
    """The terminals of a subtree's main plane, if the rest are minor parts of it.

    A window with 3D parts puts small terminals at right angles to the wall (the sides of its
    reveal, the top of its sill); they belong to the face they are set in, not to faces of
    their own.  The subtree is one face when the terminals in its largest plane (same axes,
    within DEPTH) outweigh all the others by area; the others are left out of the schema.
    Planes are set by flat terminals; a solid joins the first plane it stands in (it could
    stand in three: a box has an axis along each), else solids group among themselves."""
    groups: list[tuple[_Terminal, list[_Terminal]]] = []
    ordered = [t for t in terminals if t.flat] + [t for t in terminals if not t.flat]
    for t in ordered:
        for first, members in groups:
            if _same_plane(t, first):
                members.append(t)
                break
        else:
            groups.append((t, [t]))
        if len(groups) > 64:  # many orientations: a whole mass, not one face
            return None
    areas = [sum(_area(t) for t in members) for _, members in groups]
    best = max(range(len(groups)), key=lambda i: areas[i])
    if sum(areas) - areas[best] > MINOR * areas[best]:
        return None
    return {t.index for t in groups[best][1]}


def _face_nodes(node: _Node, out: list) -> None:
    """Collect (node, kept terminal indices) per face: the highest subtrees that lie in one
    plane, up to minor parts at other angles.  Where a rule's children are the pieces of a face
    with no rule of its own (``comp(f) { front: split(x) { ... } }``), the children in one plane
    are gathered into one face.  Lots are never gathered: two flat lots side by side lie in one
    plane, but each is a façade of its own."""
    if not node.path:  # the root: one subtree per lot
        for item in node.items:
            _face_nodes(item, out)
        return
    if node.terminals:
        kept = (
            {t.index for t in node.terminals}
            if _coplanar(node.terminals)
            else _main_plane(node.terminals)
        )
        if kept:
            out.append((node, kept))
            return
    planes: dict[tuple, _Node] = {}
    for item in node.items:
        terms = item.terminals if isinstance(item, _Node) else [item]
        if isinstance(item, _Node) and not (terms and _coplanar(terms)):
            _face_nodes(item, out)
            continue
        if not terms or not any(t.flat for t in terms):  # a solid (a roof, a box), no face
            continue
        first = _reference(terms)
        key = tuple(round(v, 5) for v in first.normal) + (
            round(_dot(first.origin, first.normal), 5),
        )
        if key not in planes:
            planes[key] = _Node(node.path, gathered=True)
            out.append(planes[key])  # keeps derivation order among faces
        planes[key].items.append(item)
        planes[key].terminals += terms
    for i, entry in enumerate(out):  # a plane of one child rule is that rule's own face
        if isinstance(entry, _Node):
            only = (
                entry.items[0]
                if len(entry.items) == 1 and isinstance(entry.items[0], _Node)
                else entry
            )
            out[i] = (only, {t.index for t in entry.terminals})
