"""Hip and gable roofs derived on L, T and U footprints (issue 3's acceptance): every roof
triangle lies on the plane that rises from one footprint edge at the pitch (or, for gables, on
a vertical gable wall over an edge), and the roof's eaves are exactly the walls' top edges."""

import json
import math

import numpy as np
import pytest
from shapely.geometry import LineString, Point, Polygon

import bgr
from bgr.interpreter.terminals import world_vertices

FOOTPRINTS = {
    "rect": [(0, 0), (16, 0), (16, 10), (0, 10)],
    "L": [(0, 0), (20, 0), (20, 10), (10, 10), (10, 20), (0, 20)],
    "T": [(0, 0), (30, 0), (30, 10), (20, 10), (20, 22), (10, 22), (10, 10), (0, 10)],
    "U": [(0, 0), (30, 0), (30, 20), (22, 20), (22, 8), (8, 8), (8, 20), (0, 20)],
}
HEIGHT, PITCH = 6.0, 30.0


def roof_triangles(tmp_path, name, kind):
    geo = tmp_path / f"{name}.geojson"
    ring = FOOTPRINTS[name] + [FOOTPRINTS[name][0]]
    geo.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    {
                        "type": "Feature",
                        "properties": {},
                        "geometry": {"type": "Polygon", "coordinates": [ring]},
                    }
                ],
            }
        )
    )
    src = (
        f"Lot --> extrude({HEIGHT}) comp(f) {{ top: roof({kind}, {PITCH}) Roof | side: Wall }}\n"
        "terminal Roof, Wall\n"
    )
    t = bgr.derive(bgr.load(src), lot=str(geo)).terminals
    rows = [i for i, lab in enumerate(t.label) if lab == "Roof"]
    assert len(rows) == 1
    mesh = t.library.meshes[t.mesh[rows[0]]]
    world = world_vertices(t, np.array(rows), mesh)[0]
    # back to footprint coordinates: east = x, north = -z, up = y
    pts = np.column_stack([world[:, 0], -world[:, 2], world[:, 1] - HEIGHT])
    return pts[mesh.faces]


def edges(name):
    ring = FOOTPRINTS[name]
    return [
        (np.array(ring[i], float), np.array(ring[(i + 1) % len(ring)], float))
        for i in range(len(ring))
    ]


def on_edge_plane(tri, a, b, inside, tol=1e-6):
    """The triangle lies on the plane rising inward from edge a-b at the pitch."""
    d = b - a
    normal = np.array([-d[1], d[0]]) / np.linalg.norm(d)
    if not inside(a + (b - a) / 2 + normal * 1e-3):
        normal = -normal
    dist = (tri[:, :2] - a) @ normal
    return np.allclose(tri[:, 2], math.tan(math.radians(PITCH)) * dist, atol=tol)


def on_gable_wall(tri, a, b, tol=1e-6):
    """The triangle stands vertically over the edge a-b."""
    line = LineString([a, b])
    return all(line.distance(Point(p)) < tol for p in tri[:, :2])


@pytest.mark.parametrize("name", list(FOOTPRINTS))
@pytest.mark.parametrize("kind", ["hip", "gable"])
def test_roof_faces_lie_on_edge_planes(tmp_path, name, kind):
    poly = Polygon(FOOTPRINTS[name])

    def inside(p):
        return poly.contains(Point(p))

    tris = roof_triangles(tmp_path, name, kind)
    assert np.isfinite(tris).all() and tris[:, :, 2].min() > -1e-6
    for tri in tris:
        ok = any(on_edge_plane(tri, a, b, inside) for a, b in edges(name))
        if kind == "gable" and not ok:
            ok = any(on_gable_wall(tri, a, b) for a, b in edges(name))
        assert ok, f"a roof triangle on no edge plane: {tri.round(4).tolist()}"


@pytest.mark.parametrize("name", list(FOOTPRINTS))
@pytest.mark.parametrize("kind", ["hip", "gable"])
def test_roof_eaves_are_the_wall_tops(tmp_path, name, kind):
    tris = roof_triangles(tmp_path, name, kind)
    count = {}
    for tri in tris:
        for i in range(3):
            p, q = tuple(tri[i].round(6)), tuple(tri[(i + 1) % 3].round(6))
            key = tuple(sorted([p, q]))
            count[key] = count.get(key, 0) + 1
    boundary = [k for k, c in count.items() if c == 1]
    eaves = [k for k in boundary if abs(k[0][2]) < 1e-6 and abs(k[1][2]) < 1e-6]
    ring = LineString(FOOTPRINTS[name] + [FOOTPRINTS[name][0]])
    for p, q in eaves:  # every eave segment lies on the footprint's outline ...
        mid = ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)
        for pt in (p[:2], q[:2], mid):
            assert ring.distance(Point(pt)) < 1e-6
    # ... and together they cover all of it
    assert sum(math.dist(p[:2], q[:2]) for p, q in eaves) == pytest.approx(ring.length, abs=1e-6)
    # a hip roof is closed above the footprint: its only open edges are the eaves
    if kind == "hip":
        assert len(eaves) == len(boundary)


@pytest.mark.parametrize(
    "w, d, overhang", [(14.3, 11.2, 0.4), (8, 12, 0), (10, 10, 0.3), (20, 3, 0.5)]
)
def test_closed_form_rectangle_hip_matches_the_straight_skeleton(w, d, overhang):
    import trimesh

    from bgr.interpreter.geometry.rect_roofs import rectangle_hip
    from bgr.interpreter.geometry.roofs import roof_mesh

    general = roof_mesh(np.array([[0, 0], [w, 0], [w, d], [0, d]], float), "hip", 30, overhang)
    v, f = rectangle_hip(w, d, 30, overhang)
    used = lambda verts, faces: sorted(set(map(tuple, np.round(verts[np.unique(faces)], 6))))  # noqa: E731
    assert used(v, f) == used(general.vertices, general.faces)
    fast = trimesh.Trimesh(v, f, process=False)
    assert fast.area == pytest.approx(
        trimesh.Trimesh(general.vertices, general.faces, process=False).area
    )
    assert (fast.face_normals[:, 2] > 0).all()
