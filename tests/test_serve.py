"""``bgr serve``'s server without a browser (starlette's test client; issue 32): it derives on
start and on every save, keeps the last good model beside an error, serves only its own files
and the model, refuses other hosts, and 100 rapid saves leave one worker and no leak."""

from __future__ import annotations

import gc
import os
import time
from pathlib import Path

import pytest

pytest.importorskip("starlette")
pytest.importorskip("watchfiles")
psutil = pytest.importorskip("psutil")

from starlette.testclient import TestClient  # noqa: E402

from bgr.editor.derivation import Request  # noqa: E402
from bgr.editor.serve import Server  # noqa: E402

pytestmark = pytest.mark.xdist_group("serve")

HOUSE = """attr floors = 3
@Range(min = 2, max = 12)
attr width = 10
terminal Wall, Roof
Lot --> s(width, 0, 8) extrude(floors * 3) comp(f) { side: Wall | top: Roof }
"""


def wait_for(check, seconds: float = 20.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        found = check()
        if found:
            return found
        time.sleep(0.05)
    raise AssertionError("timed out")


@pytest.fixture
def served(tmp_path):
    grammar = tmp_path / "house.bgr"
    grammar.write_text(HOUSE)
    server = Server(Request(str(grammar)))
    with TestClient(server.app()) as client:
        wait_for(lambda: client.get("/state").json()["version"] >= 1)
        yield server, client, grammar


def test_the_model_is_derived_and_served(served):
    server, client, _ = served
    state = client.get("/state").json()
    assert state["file"] == "house.bgr" and state["errors"] == []
    assert state["attrs"]["width"]["range"]["max"] == 12  # the inspector's slider range
    glb = client.get("/model.glb")
    assert glb.status_code == 200 and glb.content[:4] == b"glTF"
    assert glb.headers["content-type"] == "model/gltf-binary"
    picked = client.get("/pick", params={"x": 5, "y": 9, "z": 4}).json()  # on the roof
    assert picked["found"] and picked["label"] == "Roof" and picked["path"].startswith("Lot")
    assert "index.html" not in client.get("/").text and "<title>" in client.get("/").text


def test_a_save_derives_again_and_a_broken_one_keeps_the_last_good_model(served):
    server, client, grammar = served
    first = client.get("/model.glb").content
    grammar.write_text(HOUSE.replace("floors = 3", "floors = 5"))
    wait_for(lambda: client.get("/state").json()["version"] >= 2, 10)
    assert client.get("/model.glb").content != first
    good = client.get("/model.glb").content
    grammar.write_text(HOUSE.replace("extrude(floors * 3)", "extrude(floors * )"))
    errors = wait_for(lambda: client.get("/state").json()["errors"], 10)
    assert errors[0]["line"] == 5 and errors[0]["source"].startswith("Lot -->")
    assert client.get("/model.glb").content == good  # the last good model stays
    grammar.write_text(HOUSE)
    wait_for(lambda: client.get("/state").json()["version"] >= 3, 10)
    assert client.get("/state").json()["errors"] == []


def test_settings_derive_again_and_give_the_command_line(served):
    server, client, _ = served
    assert client.post("/settings", json={"seed": 4, "attrs": {"floors": 6}}).json()["ok"]
    wait_for(lambda: client.get("/state").json()["version"] >= 2, 10)
    state = client.get("/state").json()
    assert state["seed"] == 4 and state["values"] == {"floors": 6}
    command = client.get("/command").json()["command"]
    assert "--seed 4" in command and "--set floors=6" in command
    assert client.post("/settings", json={"attrs": {"floors": [1]}}).status_code == 400
    # a runaway or wrong setting is an error in the page, not a dead server
    client.post("/settings", json={"attrs": {"nowhere": 1}})
    assert wait_for(lambda: client.get("/state").json()["errors"], 10)


@pytest.mark.parametrize(
    "path",
    ["/static/../serve.py", "/static/%2e%2e/serve.py", "/static/..%2fserve.py", "/etc/passwd",
     "/static/vendor/../../serve.py", "/model.glb/../../serve.py"],
)  # fmt: skip
def test_nothing_but_its_own_files_is_served(served, path):
    _, client, _ = served
    response = client.get(path)
    assert response.status_code == 404
    assert "starlette" not in response.text and "import" not in response.text


def test_other_hosts_are_refused(served):
    _, client, _ = served
    assert client.get("/state", headers={"host": "evil.example"}).status_code == 400
    assert client.get("/state", headers={"host": "127.0.0.1:8000"}).status_code == 200


def test_a_hundred_rapid_saves_leave_one_worker_and_no_leak(served):
    server, client, grammar = served
    me = psutil.Process(os.getpid())

    def workers() -> int:
        """Derivation workers: the children of the forkserver this process started them from
        (multiprocessing's own forkserver and resource tracker are not workers)."""
        servers = [
            c for c in me.children() if c.is_running() and "forkserver" in " ".join(c.cmdline())
        ]
        return sum(len([w for w in s.children() if w.is_running()]) for s in servers)

    baseline = me.memory_info().rss
    for i in range(100):
        grammar.write_text(HOUSE.replace("floors = 3", f"floors = {2 + i % 5}"))
        time.sleep(0.01)
    grammar.write_text(HOUSE.replace("floors = 3", "floors = 7"))
    wait_for(lambda: client.get("/state").json()["values"] == {} and _floors(client) == 7, 30)
    gc.collect()
    assert workers() == 1
    assert me.memory_info().rss - baseline < 100 * 2**20
    assert server.session.derivations < 100  # saves that came together were derived once


def _floors(client) -> int | None:
    """The floors of the model shown, from its height (3 m a floor)."""
    picked = client.get("/pick", params={"x": 5, "y": 100, "z": 4}).json()
    if not picked.get("found"):
        return None
    import trimesh

    glb = client.get("/model.glb").content
    scene = trimesh.load(trimesh.util.wrap_as_stream(glb), file_type="glb")
    return round(scene.bounds[1][1] / 3)


def test_the_served_file_is_only_the_grammar_given(tmp_path):
    # the page lists no other file of the folder, and /model.glb before a model is a 404
    (tmp_path / "secret.txt").write_text("no")
    grammar = tmp_path / "bad.bgr"
    grammar.write_text("Lot --> extrude(")
    server = Server(Request(str(grammar)))
    with TestClient(server.app()) as client:
        wait_for(lambda: client.get("/state").json()["errors"])
        assert client.get("/model.glb").status_code == 404
        assert client.get("/static/secret.txt").status_code == 404
    assert Path(grammar).read_text() == "Lot --> extrude("


def test_a_runaway_derivation_is_stopped_and_the_server_goes_on(tmp_path):
    grammar = tmp_path / "runaway.bgr"
    # four million pieces: the server's timeout stops it before the shape budget would
    grammar.write_text("terminal A\nLot --> split(x) { ~0.01: split(z) { ~0.01: A }* }*\n")
    server = Server(Request(str(grammar)), timeout=2.0)
    with TestClient(server.app()) as client:
        errors = wait_for(lambda: client.get("/state").json()["errors"], 20)
        assert "took more than 2 s and was stopped" in errors[0]["message"]
        grammar.write_text("terminal A\nLot --> extrude(3) A\n")
        wait_for(lambda: client.get("/state").json()["version"] >= 1, 20)
        assert client.get("/state").json()["errors"] == []


def test_saving_an_imported_file_derives_again_and_the_socket_pushes_the_glb(tmp_path):
    (tmp_path / "parts").mkdir()
    part = tmp_path / "parts" / "block.bgr"
    part.write_text("terminal A\nattr h = 3\nBlock --> extrude(h) A\n")
    grammar = tmp_path / "main.bgr"
    grammar.write_text('import "parts/block.bgr" as b\nLot --> b.Block\n')
    server = Server(Request(str(grammar)))
    with TestClient(server.app()) as client, client.websocket_connect("/ws") as socket:
        first = socket.receive_json()
        assert first["type"] == "model" and socket.receive_bytes()[:4] == b"glTF"
        part.write_text("terminal A\nattr h = 9\nBlock --> extrude(h) A\n")
        second = socket.receive_json()
        assert second["type"] == "model" and second["version"] == first["version"] + 1
        glb = socket.receive_bytes()
        assert glb == client.get("/model.glb").content


def test_the_lot_picker_derives_one_footprint(tmp_path):
    import json

    features = [
        {
            "type": "Feature",
            "id": name,
            "properties": {},
            "geometry": {
                "type": "Polygon",
                "coordinates": [[[x, 0], [x + 10, 0], [x + 10, 8], [x, 8], [x, 0]]],
            },
        }
        for name, x in (("left", 1000), ("right", 1030))
    ]
    lots = tmp_path / "lots.geojson"
    lots.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    grammar = tmp_path / "block.bgr"
    grammar.write_text("terminal A\nLot --> extrude(5) A\n")
    server = Server(Request(str(grammar), lot=str(lots)))
    with TestClient(server.app()) as client:
        state = wait_for(lambda: (s := client.get("/state").json())["version"] >= 1 and s)
        assert state["features"] == ["left", "right"]
        both = client.get("/state").json()["model"]["terminals"]
        client.post("/settings", json={"feature": 1})
        wait_for(lambda: client.get("/state").json()["version"] >= 2, 10)
        state = client.get("/state").json()
        assert state["feature"] == 1 and state["model"]["terminals"] == both / 2
