"""The parse tree: buildings as stacks of typed components, and neighbourhood patterns found by
Girvan-Newman clustering (paper, section V).

* A **building** is the stack of components cut from one input object.  Its frame is its lowest
  component's; each component sits in it by a relative placement (a turn about the vertical and a
  translation) and a size.  Buildings whose stacks agree (the same types, placements equal on the
  level's grid) are one **building kind**: a non-terminal with one rule.
* **Neighbourhood patterns**: the graph of building kinds has an edge where instances of two
  kinds are neighbours (midpoints within tau, equation 3), weighted by the paper's distance
  D = (w_mu mu + w_sigma sigma) / r (equations 8-11, sums over neighbouring pairs).  Girvan-Newman
  (networkx) divides each connected part of that graph into communities, recursively, which gives
  the tree.  Graphs of more than GN_MAX_NODES kinds are first divided by Louvain communities
  (Girvan-Newman is O(m^2 n)), and Girvan-Newman runs inside each.
* **Instances of a tree node**: the instances of its children that are neighbours (connected
  components of the neighbour graph).  An instance's placements of its members, relative to its
  first member, are its signature; a signature that occurs twice or more becomes a rule
  ``Group --> [ matrix(E) A ] [ matrix(E) A ] [ matrix(E) B ]`` with the placements averaged over
  its instances (equation 7); instances with a signature of their own are not grouped, and their
  members go on up the tree.  The root is the axiom: it places what reaches it.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

import networkx as nx
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

# more kinds than this in one connected part: Louvain first (see above).  Girvan-Newman on the
# 10,000-building synthetic city took 37 s of 72 with 60 here, 0.4 s of 34 with 30.
GN_MAX_NODES = 30


@dataclass
class Placement:
    """Where a child sits in its parent's frame: a turn about the vertical, a translation, and
    (for components) the scope size."""

    rule: str
    angle: float  # degrees about bgr's y
    offset: np.ndarray  # (3,)
    size: np.ndarray | None = None


@dataclass
class Rule:
    """A non-terminal: its children's placements, and how many instances use it."""

    name: str
    children: list[Placement]
    uses: int = 0
    comment: str = ""


@dataclass
class Instance:
    """One instance of a rule in the world: its frame and midpoint."""

    rule: str
    frame: np.ndarray  # (4, 4)
    midpoint: np.ndarray  # (3,)


@dataclass
class Tree:
    rules: list[Rule] = field(default_factory=list)
    axiom: list[Placement] = field(default_factory=list)
    tau: float = 0.0
    kinds: int = 0
    groups: int = 0


def turn_of(frame: np.ndarray) -> float:
    """The angle (degrees) of a frame turned about bgr's y: its x axis is (cos a, 0, -sin a)."""
    return float(np.degrees(np.arctan2(-frame[2, 0], frame[0, 0])))


def relative(parent: np.ndarray, child: np.ndarray) -> tuple[float, np.ndarray]:
    """The child's frame in the parent's: (angle, offset)."""
    rel = np.linalg.inv(parent) @ child
    return turn_of(rel), rel[:3, 3]


def relative_all(parent: np.ndarray, children: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`relative` of many children at once (``parent`` one frame or one per child):
    angles (n,) and offsets (n, 3), the same numbers (stacked products compute each alone)."""
    rel = np.linalg.inv(parent) @ children
    return np.degrees(np.arctan2(-rel[:, 2, 0], rel[:, 0, 0])), rel[:, :3, 3]


def _grid(level: int) -> tuple[float, float]:
    """(metres, degrees) grids on which placements must agree to share a rule: 0.1 mm and 1e-5
    degrees at the exact level 0 (errors well under 1 mm), coarser above."""
    if level == 0:
        return 1e-4, 1e-5
    scale = 2.0 ** (level - 1)
    return 0.25 * scale, 1.0 * scale


def level_digits(level: int) -> int:
    """Decimals of the lengths written at ``level`` above 0: a tenth of the grid its building
    kinds merge on (centimetres at levels 1 and 2, decimetres above), so that rounding adds at
    most 5 per cent of what the level already moves (Zurich's level 3: 50,031 -> 44,044 bytes
    with its turns at a tenth of a degree, Chamfer 0.462 -> 0.478 m; docs/benchmarks.md)."""
    return int(max(1, np.ceil(-np.log10(_grid(level)[0] / 10))))


def _key(p: Placement, grid: tuple[float, float]) -> tuple:
    metres, degrees = grid
    angle = int(np.rint((p.angle % 360.0) / degrees)) % int(np.rint(360.0 / degrees))
    offset = tuple(np.rint(p.offset / metres).astype(np.int64).tolist())
    size = () if p.size is None else tuple(np.rint(p.size / metres).astype(np.int64).tolist())
    return (p.rule, angle, offset, size)


def keys_all(
    rank: np.ndarray,
    angles: np.ndarray,
    offsets: np.ndarray,
    sizes: np.ndarray | None,
    grid: tuple[float, float],
) -> np.ndarray:
    """:func:`_key` of many placements as rows of ints (n, 5 or 8): the rule's rank among the
    rule names (so that rows sort as the keys do), the angle, the offset and the size on the
    grid."""
    metres, degrees = grid
    angle = np.rint(np.remainder(angles, 360.0) / degrees).astype(np.int64)
    columns = [rank[:, None], (angle % int(np.rint(360.0 / degrees)))[:, None]]
    columns.append(np.rint(offsets / metres).astype(np.int64))
    if sizes is not None:
        columns.append(np.rint(sizes / metres).astype(np.int64))
    return np.concatenate(columns, axis=1)


def _average(placements: list[list[Placement]]) -> list[Placement]:
    """The placements of several instances of one signature, slot by slot, averaged (the
    circular mean for the angle)."""
    out = []
    for slot in zip(*placements, strict=True):
        angles = np.radians([p.angle for p in slot])
        angle = float(np.degrees(np.arctan2(np.sin(angles).mean(), np.cos(angles).mean())))
        offset = np.mean([p.offset for p in slot], axis=0)
        size = None if slot[0].size is None else np.mean([p.size for p in slot], axis=0)
        out.append(Placement(slot[0].rule, angle, offset, size))
    return out


def neighbour_radius(midpoints: np.ndarray) -> float:
    """Default tau: 1.5 times the median distance from a building to its nearest neighbour."""
    if len(midpoints) < 2:
        return 0.0
    distances, _ = cKDTree(midpoints).query(midpoints, k=2)
    return 1.5 * float(np.median(distances[:, 1]))


def kind_graph(
    kinds: np.ndarray, midpoints: np.ndarray, tau: float, w_mu: float, w_sigma: float
) -> nx.Graph:
    """The graph of building kinds with the paper's distance D on its edges (equations 8-11)."""
    graph = nx.Graph()
    graph.add_nodes_from(range(int(kinds.max()) + 1 if len(kinds) else 0))
    if tau <= 0 or len(midpoints) < 2:
        return graph
    pairs = cKDTree(midpoints).query_pairs(tau, output_type="ndarray")
    if len(pairs) == 0:
        return graph
    count = np.bincount(kinds)
    a, b = kinds[pairs[:, 0]], kinds[pairs[:, 1]]
    keep = a != b
    if not keep.any():  # only buildings of one kind near each other: no edge between kinds
        return graph
    pairs, a, b = pairs[keep], a[keep], b[keep]
    if len(pairs) == 0:  # every neighbour is of its own kind (a street of one house)
        return graph
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    delta = midpoints[pairs[:, 0]] - midpoints[pairs[:, 1]]
    dist = np.linalg.norm(delta, axis=1)  # equation 2
    mht = np.abs(delta[:, 0]) + np.abs(delta[:, 2])  # equation 4, in the ground plane
    order = np.lexsort((hi, lo))
    edges = np.column_stack([lo, hi])[order]
    starts = np.flatnonzero(np.r_[True, np.any(edges[1:] != edges[:-1], axis=1)])
    for s, e in zip(starts, np.r_[starts[1:], len(edges)], strict=True):
        k, m = int(edges[s, 0]), int(edges[s, 1])
        idx = order[s:e]
        r = len(idx)  # equation 8
        least = min(count[k], count[m])
        sigma = float(np.sqrt(np.sum((mht[idx] - mht[idx].mean()) ** 2) / least))  # eq. 9
        mu = float(dist[idx].sum() / least)  # equation 10
        graph.add_edge(k, m, D=(w_mu * mu + w_sigma * sigma) / r, r=r)  # equation 11
    return graph


def _most_valuable_edge(graph: nx.Graph):
    betweenness = nx.edge_betweenness_centrality(graph, weight="D")
    return max(betweenness, key=betweenness.get)


def communities(graph: nx.Graph, seed: int = 0) -> list:
    """The tree over the graph's nodes as nested lists: a leaf is a node, an inner node the list
    of its children (Girvan-Newman, recursively; see the module docstring)."""
    parts = [sorted(c) for c in nx.connected_components(graph)]
    parts.sort(key=lambda c: c[0])
    return [_divide(graph.subgraph(c).copy(), seed) for c in parts]


def _divide(graph: nx.Graph, seed: int):
    nodes = sorted(graph.nodes)
    if len(nodes) == 1:
        return nodes[0]
    if len(nodes) > GN_MAX_NODES:
        similarity = nx.Graph()
        similarity.add_nodes_from(nodes)
        for u, v, d in graph.edges(data=True):
            similarity.add_edge(u, v, weight=1.0 / max(d["D"], 1e-12))
        found = nx.community.louvain_communities(similarity, weight="weight", seed=seed)
        if len(found) > 1:
            groups = sorted((sorted(c) for c in found), key=lambda c: c[0])
            return [_divide(graph.subgraph(c).copy(), seed) for c in groups]
    split = next(nx.community.girvan_newman(graph, most_valuable_edge=_most_valuable_edge))
    groups = sorted((sorted(c) for c in split), key=lambda c: c[0])
    return [_divide(graph.subgraph(c).copy(), seed) for c in groups]


def group(
    tree: list,
    leaves: dict[int, list[Instance]],
    tau: float,
    grid: tuple[float, float],
    new_rule,
) -> list[Instance]:
    """The instances that reach the top of ``tree`` (a node or nested lists), making a rule with
    ``new_rule(placements, uses)`` for every signature found twice or more."""
    if not isinstance(tree, list):
        return list(leaves.get(tree, []))
    pool = [inst for child in tree for inst in group(child, leaves, tau, grid, new_rule)]
    if len(pool) < 2 or tau <= 0:
        return pool
    mid = np.array([inst.midpoint for inst in pool])
    pairs = cKDTree(mid).query_pairs(tau, output_type="ndarray")
    if len(pairs) == 0:
        return pool
    by_signature: dict[tuple, list[tuple[list[int], list[Placement], np.ndarray]]] = defaultdict(
        list
    )
    out: list[Instance] = []
    parts = _connected(len(pool), pairs)
    signed = iter(_signatures(pool, [m for m in parts if len(m) > 1], grid))
    for members in parts:
        if len(members) == 1:
            out.append(pool[members[0]])
            continue
        signature, ordered, placed, anchor = next(signed)
        by_signature[signature].append((ordered, placed, anchor))
    repeated: list[tuple[int, str, np.ndarray, list[int]]] = []
    for found in sorted(by_signature.values(), key=lambda f: min(f[0][0])):
        if len(found) < 2:
            out += [pool[i] for i in found[0][0]]
            continue
        name = new_rule(_average([placed for _, placed, _ in found]), len(found))
        for members, _, anchor in found:
            repeated.append((len(out), name, anchor, members))
            out.append(pool[members[0]])  # in its place until the midpoints are known
    means = _means(pool, [members for *_, members in repeated])
    for (k, name, anchor, _), mid in zip(repeated, means, strict=True):
        out[k] = Instance(name, anchor, mid)
    return out


def _means(pool: list[Instance], groups: list[list[int]]) -> list[np.ndarray]:
    """The mean midpoint of each group of instances (``np.mean`` of them in the group's order),
    the groups of one size at a time."""
    out: list[np.ndarray] = [np.zeros(3)] * len(groups)
    sizes = np.array([len(g) for g in groups], dtype=np.int64)
    for size in np.unique(sizes).tolist():
        which = np.flatnonzero(sizes == size).tolist()
        points = np.array([[pool[i].midpoint for i in groups[k]] for k in which])
        for k, mean in zip(which, np.mean(points, axis=1), strict=True):
            out[k] = mean
    return out


ANCHORS = 8  # at most this many members are tried as an instance's anchor


def _connected(count: int, pairs: np.ndarray) -> list[list[int]]:
    """The connected components of the graph on ``count`` nodes with edges ``pairs``, each
    sorted, in order of their least node."""
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(count, count))
    _, label = connected_components(graph, directed=False)
    order = np.argsort(label, kind="stable")
    parts = np.split(order, np.flatnonzero(np.diff(label[order])) + 1)
    return [p.tolist() for p in sorted(parts, key=lambda p: int(p[0]))]


def _signatures(
    pool: list[Instance], parts: list[list[int]], grid: tuple[float, float]
) -> list[tuple[tuple, list[int], list[Placement], np.ndarray]]:
    """The signature of each group of instances (``parts``, each sorted): its members'
    placements relative to an anchor member, on the grid, sorted.  Each member of the group's
    first rule (by name; at most ANCHORS of them) is tried as the anchor and the smallest
    signature kept (the first of equals), so that a turned copy of a pattern has the same one.

    All groups at once: the k-th anchors of every group are tried together (stacked inverses and
    products, :func:`relative_all`), and each group keeps the better of its best so far and
    its k-th.  Returns (signature, members in signature order, their placements, anchor frame)
    for each group."""
    if not parts:
        return []
    frames = np.stack([inst.frame for inst in pool])
    names = [inst.rule for inst in pool]
    rank = np.unique(names, return_inverse=True)[1].reshape(-1)
    sizes = np.array([len(p) for p in parts], dtype=np.int64)
    members = np.concatenate([np.asarray(p, dtype=np.int64) for p in parts])
    part_of = np.repeat(np.arange(len(parts)), sizes)
    starts = np.r_[0, np.cumsum(sizes)[:-1]]
    own_rank = rank[members]
    first = own_rank == np.minimum.reduceat(own_rank, starts)[part_of]  # of the first rule
    nth = np.cumsum(first) - 1
    nth -= np.r_[0, np.cumsum(first)[:-1]][starts][part_of]  # its place among them, per group
    best: dict[str, np.ndarray] = {}
    for k in range(ANCHORS):
        anchors = members[first & (nth == k)]  # the k-th anchor of each group that has one
        tried = np.flatnonzero(np.bincount(part_of[first & (nth == k)], minlength=len(parts)))
        if not len(tried):
            break
        rows = np.flatnonzero(np.isin(part_of, tried))  # their members, group by group
        local = np.searchsorted(tried, part_of[rows])
        angles, offsets = relative_all(frames[anchors][local], frames[members[rows]])
        keys = keys_all(own_rank[rows], angles, offsets, None, grid)
        order = np.lexsort((*keys.T[::-1], local))  # each group's placements by key
        found = {
            "keys": keys[order],
            "members": members[rows][order],
            "angles": angles[order],
            "offsets": offsets[order],
        }
        if k == 0:
            best = found
            best["anchor"] = anchors
            continue
        better = _less(found["keys"], best["keys"][rows], local, len(tried))
        swap = np.isin(local, np.flatnonzero(better))
        for name, value in found.items():
            best[name][rows[swap]] = value[swap]
        best["anchor"][tried[better]] = anchors[better]
    out = []
    for j, (s, e) in enumerate(zip(starts.tolist(), (starts + sizes).tolist(), strict=True)):
        ordered = best["members"][s:e].tolist()
        angles = best["angles"][s:e].tolist()
        offsets = best["offsets"][s:e]
        placed = [
            Placement(names[i], a, o) for i, a, o in zip(ordered, angles, offsets, strict=True)
        ]
        signature = (tuple(names[i] for i in ordered), best["keys"][s:e, 1:].tobytes())
        out.append((signature, ordered, placed, pool[int(best["anchor"][j])].frame))
    return out


def _less(a: np.ndarray, b: np.ndarray, group: np.ndarray, count: int) -> np.ndarray:
    """For rows ``a`` and ``b`` (equal shapes) cut into ``count`` consecutive groups: whether
    each group's rows in ``a`` come before its rows in ``b``, compared as tuples."""
    flat_a, flat_b = a.reshape(-1), b.reshape(-1)
    where = np.repeat(group, a.shape[1])
    differ = np.flatnonzero(flat_a != flat_b)
    out = np.zeros(count, dtype=bool)
    first_diff = np.unique(where[differ], return_index=True)
    at = differ[first_diff[1]]
    out[first_diff[0]] = flat_a[at] < flat_b[at]
    return out
