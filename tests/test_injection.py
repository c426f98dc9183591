"""No grammar injection (issue 25): text from an inverse module's input never becomes grammar.

Each surface of ``bgr infer`` is run through the real command line twice, once with benign names
and once with hostile ones in every text field its input has (the file name itself, object and
node names, CityJSON ids and CRS, box ids and mesh paths, captured-model names and labels,
terminal-list labels and paths): line breaks of every kind, ``#``, quotes, backslashes, ``-->``,
braces, NUL, lone surrogates and 100,000-character names.  The hostile run must end in a
success whose grammar parses to the same items as the benign one (no extra rule, attr, import
or asset; only comments and names differ), or in a located error with exit 1, never an
internal error.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import struct
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bgr.cli import main
from bgr.grammar import nodes as n
from bgr.grammar.formatter import format_module
from bgr.grammar.parser import parse
from bgr.grammar.safe_text import comment_line, comment_text, identifier, unwritable

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"

# every way to end a line (the parser's and an editor's), code that would be injected after
# each, and the characters that open strings, comments, rules and blocks
BREAKS = ["\n", "\r", "\r\n", "\u2028", "\u2029", "\x85", "\x0b", "\x0c"]
PAYLOAD = (
    "".join(
        f'{b}attr evil{i} = 1{b}import "x{i}.bgr" as m{i}{b}Evil{i} --> NIL'
        for i, b in enumerate(BREAKS)
    )
    + " # \" ' \\ --> { } // \u202e"
)
# a file name holds no '/' and at most 255 bytes
FILE_PAYLOAD = "".join(f"{b}attr evil{i} = 1" for i, b in enumerate(BREAKS)) + " # \" ' \\ -->{}"
EVIL_FILE = "n\nattr evil = 1\n#"  # the issue's reproducer: an OBJ named n⏎attr evil = 1⏎#.obj
LONG = "x" * 100_000


def run(argv: list[str], capsys) -> tuple[int, str]:
    """bgr's exit status and standard error for ``argv``, run in this process (standard error
    taken as a str: it holds what a terminal shows with backslashes, lone surrogates too)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main([str(a) for a in argv])
    capsys.readouterr()
    return code, err.getvalue()


def shape(text: str) -> Counter:
    """What a grammar declares, names aside: how many items of each kind, and the names of its
    attrs and of what it imports (an injected line would add to or change these)."""
    module = parse(text, "<inferred>")
    out: Counter = Counter(type(item).__name__ for item in module.items)
    out.update(f"attr {i.name}" for i in module.items if isinstance(i, n.Attr))
    out.update(f"import {i.alias}" for i in module.items if isinstance(i, (n.Import, n.Start)))
    return out


def assert_clean(text: str) -> None:
    """No line of ``text`` but a comment or code the inverse module writes: nothing starts
    with what the payload injects, and no comment holds a character an editor breaks at."""
    for line in text.split("\n"):
        stripped = line.strip()
        assert not stripped.startswith(("attr evil", "import", "Evil", "start")), line[:80]
        if stripped.startswith("#"):
            assert all(c.isprintable() for c in stripped), repr(stripped[:200])
            assert len(stripped) < 1000
    assert "\r" not in text and "\x00" not in text


def outcome(argv: list[str], capsys, output: Path, benign: str | None) -> str | None:
    """Run a hostile case: exit 0 and a grammar shaped as ``benign``'s (returned), or exit 1
    with a located message (``file: error: ...``), never an internal error."""
    code, err = run(argv, capsys)
    assert "internal error" not in err and "Traceback" not in err, err[-2000:]
    if code != 0:
        assert code == 1, err[-2000:]
        assert ": error: " in err, err[-2000:]
        assert not output.exists()
        return None
    text = output.read_text(encoding="utf-8")
    assert_clean(text)
    if benign is not None:
        assert shape(text) == shape(benign)
    return text


# ---- the helpers -----------------------------------------------------------------------------


@pytest.mark.parametrize("value", [PAYLOAD, EVIL_FILE, LONG, "a\x00b", "\udcff", "é ok"])
def test_comment_text_is_one_printable_line_of_bounded_length(value):
    safe = comment_text(value)
    assert all(c.isprintable() for c in safe) and len(safe) <= 203
    assert parse(f"# {safe}\nLot --> NIL\n").items == parse("Lot --> NIL\n").items
    if value == "é ok":
        assert safe == value  # printable text is kept as it is


@settings(max_examples=300, deadline=None)
@given(st.text(), st.text())
def test_any_text_in_a_comment_or_a_name_leaves_the_grammar_as_it_is(comment, name):
    """Whatever the input holds (any code points, surrogates included), the comment and the
    rule name built from it parse to one comment and one rule."""
    rule = identifier(name)
    text = f"{comment_line('# ' + comment_text(comment))}\n{rule} --> NIL\n"
    assert parse(text).items == [n.Rule(rule, [], n.Sequence([n.Nil()]))]
    text.encode("utf-8")  # writable as it is


def test_comment_line_keeps_parsed_comments_and_mends_built_ones():
    for parsed in ("# a\ttab", "// x \u2028 y", "#"):
        assert comment_line(parsed) == parsed
    assert comment_line("attr x = 1") == "# attr x = 1"
    assert "\n" not in comment_line("# a\nattr x = 1\r\x00")


@pytest.mark.parametrize(
    "value", [PAYLOAD, "", "123", "split", "NIL", "Lot", "é", "_", LONG, "\x00\ud800"]
)
def test_identifier_is_a_legal_fresh_name(value):
    name = identifier(value, taken={"Lot"})
    assert name.isascii() and name[0].isalpha() and len(name) <= 70
    assert name not in ("split", "NIL", "Lot")
    assert parse(f"{name} --> NIL\n").rules()[0].name == name


def test_unwritable_names_what_a_string_cannot_hold():
    assert unwritable('a\nb"c\\') is None
    assert "NUL" in unwritable("a\x00")
    assert "\\udcff" in unwritable("\udcff")


def test_the_formatter_never_writes_a_built_comment_as_code():
    module = n.Module(
        [n.Attr("width", n.Number(1.0), pos=n.Pos(2, 1, 2, 2))],
        comments=[n.Comment("# from x\nattr evil = 1\r#", 1, 1, True)],
        source="#\nx\n",
    )
    text = format_module(module)
    assert shape(text) == Counter({"Attr": 1, "attr width": 1})


@settings(max_examples=300, deadline=None)
@given(st.text())
def test_any_built_comment_stays_a_comment(text):
    """The formatter's own guard: a comment a module built holds any text and stays one."""
    module = n.Module(
        [n.Attr("width", n.Number(1.0), pos=n.Pos(2, 1, 2, 2))],
        comments=[n.Comment(text, 1, 1, True)],
        source="#\nx\n",
    )
    assert parse(format_module(module)).items == module.items


def test_a_long_rule_name_without_parameters_stays_on_one_line():
    name = "A" * 70
    assert format_module(parse(f"{name} --> NIL\n")) == f"{name} --> NIL\n"


# ---- city: OBJ, PLY, glTF, GLB, CityJSON ------------------------------------------------------

CUBE_V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def obj_text(name: str) -> str:
    """Two cubes, named (``o`` and ``g``) ``name``."""
    lines = []
    for k, dx in enumerate((0, 5)):
        lines += [f"o {name}{k}", f"g {name}"]
        lines += [f"v {x + dx} {y} {z}" for x, y, z in CUBE_V]
        lines += ["f " + " ".join(str(8 * k + i + 1) for i in f) for f in CUBE_F]
    return "\n".join(lines) + "\n"


def ply_bytes(comment: str) -> bytes:
    head = ["ply", "format ascii 1.0", f"comment {comment}", "element vertex 8"]
    head += ["property float x", "property float y", "property float z", "element face 6"]
    head += ["property list uchar int vertex_indices", "end_header"]
    body = [f"{x} {y} {z}" for x, y, z in CUBE_V] + [f"4 {' '.join(map(str, f))}" for f in CUBE_F]
    return ("\n".join(head + body) + "\n").encode("utf-8", "surrogatepass")


def gltf_doc(name: str) -> tuple[dict, bytes]:
    """A glTF of one cube in a node and a mesh named ``name``, and its buffer."""
    tris = [t for f in CUBE_F for t in ((f[0], f[1], f[2]), (f[0], f[2], f[3]))]
    data = struct.pack("<24f", *[c for v in CUBE_V for c in v])
    data += struct.pack(f"<{3 * len(tris)}H", *[i for t in tris for i in t])
    doc = {
        "asset": {"version": "2.0", "generator": name},
        "scene": 0,
        "scenes": [{"name": name, "nodes": [0]}],
        "nodes": [{"name": name, "mesh": 0}],
        "meshes": [{"name": name, "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(data)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96},
            {"buffer": 0, "byteOffset": 96, "byteLength": len(data) - 96},
        ],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 8,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 1],
            },
            {"bufferView": 1, "componentType": 5123, "count": 3 * len(tris), "type": "SCALAR"},
        ],
    }
    return doc, data


def gltf_bytes(name: str) -> bytes:
    doc, data = gltf_doc(name)
    uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    doc["buffers"][0]["uri"] = uri
    return json.dumps(doc).encode()


def glb_bytes(name: str) -> bytes:
    doc, data = gltf_doc(name)
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    chunks = struct.pack("<I4s", len(text), b"JSON") + text
    chunks += struct.pack("<I4s", len(data), b"BIN\0") + data
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def cityjson_bytes(name: str, crs: str) -> bytes:
    """A Building (a cube) with id ``name`` and a Road (carried through, so its id and type are
    written in a comment) with id ``name``-road, in CRS ``crs``."""
    v = [[x * 10, y * 10, z * 10] for x, y, z in CUBE_V]
    shell = [[list(f)] for f in CUBE_F]
    doc = {
        "type": "CityJSON",
        "version": "2.0",
        "transform": {"scale": [1, 1, 1], "translate": [0, 0, 0]},
        "metadata": {"referenceSystem": crs},
        "CityObjects": {
            name: {
                "type": "Building",
                "geometry": [{"type": "Solid", "lod": "2", "boundaries": [shell]}],
            },
            name + "-road": {
                "type": "Road",
                "geometry": [
                    {"type": "MultiSurface", "lod": "2", "boundaries": [[[8, 9, 10, 11]]]}
                ],
            },
        },
        "vertices": v + [[0, -50, 0], [40, -50, 0], [40, -20, 0], [0, -20, 0]],
    }
    return json.dumps(doc).encode()


CITY = {
    ".obj": lambda name: obj_text(name).encode("utf-8", "surrogatepass"),
    ".ply": ply_bytes,
    ".gltf": gltf_bytes,
    ".glb": glb_bytes,
    ".city.json": lambda name: cityjson_bytes(name, "EPSG:7415 " + name),
}
NAMES = {"payload": PAYLOAD, "long": LONG, "nul": "a\x00b", "surrogate": "\udcff\ud800"}


def city_case(tmp_path: Path, suffix: str, file_stem: str, text_name: str, capsys, benign):
    folder = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    folder.mkdir()
    source = folder / (file_stem + suffix)
    source.write_bytes(CITY[suffix](text_name))
    out = folder / "out.bgr"
    return outcome(["infer", "--kind", "city", source, "-o", out], capsys, out, benign)


@pytest.mark.parametrize("suffix", list(CITY))
def test_city_inputs_cannot_inject_grammar(tmp_path, capsys, suffix):
    benign = city_case(tmp_path, suffix, "city", "house", capsys, None)
    assert benign is not None
    # the input's own text fields: object, node and mesh names, ids, CRS, PLY comments
    for name in NAMES.values():
        city_case(tmp_path, suffix, "city", name, capsys, benign)
    # the file name: the issue's reproducer, the payload (no '/' in a file name), undecodable
    # bytes (a surrogate to Python), and a name as long as the system takes
    stems = [EVIL_FILE, FILE_PAYLOAD, "\udcff", "y" * (250 - len(suffix))]
    for stem in stems:
        text = city_case(tmp_path, suffix, stem, "house", capsys, benign)
        assert text is not None, stem  # nothing wrong with the file: it must infer
        assert text.split("\n")[0].startswith("# Inferred by bgr infer --kind city from ")


def test_the_issue_reproducer(tmp_path, capsys):
    """An OBJ named ``n⏎attr evil = 1⏎#.obj`` writes no ``attr evil`` line."""
    source = tmp_path / "n\nattr evil = 1\n#.obj"
    source.write_text(obj_text("box"))
    out = tmp_path / "out.bgr"
    assert run(["infer", source, "-o", out], capsys)[0] == 0
    text = out.read_text()
    assert text.startswith("# Inferred by bgr infer --kind city from n\\nattr evil = 1\\n#.obj:")
    assert not any(isinstance(i, n.Attr) for i in parse(text).items)


# ---- boxes ------------------------------------------------------------------------------------


def boxes_doc(name: str, mesh: str | None) -> dict:
    """A root split into two boxes along x, the first with id ``name`` and mesh ``mesh``."""
    first = {"id": name, "min": [0, 0, 0], "max": [5, 10, 10], "children": []}
    if mesh is not None:
        first["mesh"] = mesh
    second = {"id": "b" + name, "min": [5, 0, 0], "max": [10, 10, 10]}
    second["behavior"] = {"x": "R", "y": "S", "z": "F"}
    second["children"] = []
    root = {"id": "r" + name, "min": [0, 0, 0], "max": [10, 10, 10], "children": [first, second]}
    return {"root": root}


def boxes_case(tmp_path: Path, stem: str, name: str, mesh: str | None, capsys, benign):
    folder = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    folder.mkdir()
    if mesh is not None and "\x00" not in mesh and "/" not in mesh:
        # no such file name (too long, not text): the reader must say so
        with contextlib.suppress(OSError, UnicodeEncodeError):
            (folder / mesh).write_text(obj_text("part"))
    source = folder / (stem + ".json")
    source.write_text(json.dumps(boxes_doc(name, mesh)))
    out = folder / "out.bgr"
    return outcome(["infer", "--kind", "boxes", source, "-o", out], capsys, out, benign)


def test_boxes_cannot_inject_grammar(tmp_path, capsys):
    benign = boxes_case(tmp_path, "boxes", "porch", "porch.obj", capsys, None)
    assert benign is not None
    for name in NAMES.values():
        text = boxes_case(tmp_path, "boxes", name, "porch.obj", capsys, benign)
        assert text is not None  # an id is any string: it must infer
        # the mesh path (a file of that name, where the system allows one)
        boxes_case(tmp_path, "boxes", "porch", name[:200] + ".obj", capsys, benign)
    for stem in (EVIL_FILE, FILE_PAYLOAD, "\udcff"):
        assert boxes_case(tmp_path, stem, "porch", "porch.obj", capsys, benign) is not None


def test_retarget_refuses_a_mesh_path_no_file_has(tmp_path, capsys):
    source = tmp_path / "boxes.json"
    source.write_text(json.dumps(boxes_doc("porch", "\ud800.obj")))
    code, err = run(["retarget", source, "--size", "12,10,10", "-o", tmp_path / "r.json"], capsys)
    assert code == 1 and "boxes.json: error: " in err and "\\ud800" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["boxes.json"]


def test_an_assets_folder_a_grammar_cannot_name_is_refused(tmp_path, capsys):
    source = tmp_path / "city.obj"
    source.write_text(obj_text("house"))
    code, err = run(["infer", source, "-o", tmp_path / "\udcff.bgr"], capsys)
    assert code == 2 and "--assets DIR" in err and "internal error" not in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["city.obj"]


def test_a_box_mesh_path_is_a_string_literal(tmp_path, capsys):
    mesh = 'a"\\b\n#c -->{}.obj'
    text = boxes_case(tmp_path, "boxes", "porch", mesh, capsys, None)
    assets = [i for i in parse(text).items if isinstance(i, n.Asset)]
    assert [Path(a.path).name for a in assets] == [mesh]


# ---- captured models and terminal lists (bgr infer --kind schema) ------------------------------


def captured_case(tmp_path: Path, stem: str, edit, capsys, benign):
    folder = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    folder.mkdir()
    doc = json.loads((EXAMPLES / "captured" / "corner_shop.json").read_text())
    edit(doc)
    source = folder / (stem + ".json")
    source.write_text(json.dumps(doc))
    out = folder / "out.bgr"
    return outcome(["infer", "--kind", "schema", source, "-o", out], capsys, out, benign)


def _set_everywhere(doc: dict, key: str, value: str) -> None:
    """Every ``key`` in the document (names, ids, labels) set to ``value``, keeping them apart."""
    stack, count = [doc], 0
    while stack:
        item = stack.pop()
        if isinstance(item, dict):
            if isinstance(item.get(key), str):
                item[key] = f"{value}{count}"
                count += 1
            stack += list(item.values())
        elif isinstance(item, list):
            stack += item


def test_captured_model_names_and_file_names_cannot_inject_grammar(tmp_path, capsys):
    benign = captured_case(tmp_path, "shop", lambda d: None, capsys, None)
    assert benign is not None
    for stem in (EVIL_FILE, FILE_PAYLOAD, "\udcff"):
        text = captured_case(tmp_path, stem, lambda d: None, capsys, benign)
        assert text is not None
    for key in ("name", "id"):
        twin = captured_case(
            tmp_path, "shop", lambda d, k=key: _set_everywhere(d, k, "w"), capsys, None
        )
        assert captured_case(
            tmp_path, "shop", lambda d, k=key: _set_everywhere(d, k, PAYLOAD), capsys, twin
        )


@pytest.mark.slow
def test_captured_models_cannot_inject_grammar(tmp_path, capsys):
    """Every text field of a captured model, every hostile name (about 20 s)."""
    for key in ("name", "id", "label", "plain", "roof"):
        # the same edit with plain words: names told apart as the hostile ones are
        twin = captured_case(
            tmp_path, "shop", lambda d, k=key: _set_everywhere(d, k, "w"), capsys, None
        )
        for name in NAMES.values():

            def edit(doc, key=key, name=name):
                _set_everywhere(doc, key, name)

            captured_case(tmp_path, "shop", edit, capsys, twin)


def terminal_list(tmp_path: Path, capsys) -> dict:
    grammar = tmp_path / "facade.bgr"
    grammar.write_text(
        "version 1\nterminal Win, Wall\nattr height = 6\n"
        "Lot --> extrude(height) comp(f) {\n"
        "    front: Facade | top: NIL | bottom: NIL | side: Facade }\n"
        "Facade --> split(y) { 3: Floor | 3: Floor }\n"
        'Floor --> split(x) { ~1: label("win") Win | 2: label("wall") Wall }*\n'
    )
    out = tmp_path / "facade.json"
    assert run(["derive", grammar, "-o", out], capsys)[0] == 0
    return json.loads(out.read_text())


def terminals_case(tmp_path: Path, stem: str, doc: dict, capsys, benign):
    folder = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    folder.mkdir()
    source = folder / (stem + ".json")
    source.write_text(json.dumps(doc))
    out = folder / "out.bgr"
    return outcome(["infer", "--kind", "schema", source, "-o", out], capsys, out, benign)


def test_terminal_lists_cannot_inject_grammar(tmp_path, capsys):
    base = terminal_list(tmp_path, capsys)
    benign = terminals_case(tmp_path, "facade", base, capsys, None)
    assert benign is not None
    for name in NAMES.values():
        doc = json.loads(json.dumps(base))
        for t in doc["terminals"]:
            if t["label"] == "win":
                t["label"], t["rule"], t["color"] = name, name, name
            t["path"] = t["path"].replace("Floor", name[:1000])
        text = terminals_case(tmp_path, "facade", doc, capsys, None)
        if text is not None:  # a label is any text: written as a string, named by a safe rule
            labels = [
                s.args[0].value
                for r in parse(text).rules()
                for s in r.body.steps
                if isinstance(r.body, n.Sequence) and getattr(s, "name", "") == "label"
            ]
            # a label that is a plain name is a terminal of that name; any other is a string
            assert name in labels or (name.isidentifier() and f" {name}" in text)
            assert shape(text) - Counter({"Rule": 99}) == shape(benign) - Counter({"Rule": 99})
    for stem in (EVIL_FILE, FILE_PAYLOAD, "\udcff"):
        assert terminals_case(tmp_path, stem, base, capsys, benign) is not None


# ---- the terminal -----------------------------------------------------------------------------

ESCAPES = "\x1b[2J\x1b]0;owned\x07\r\x00\u202e"  # clear, retitle, return, NUL, right-to-left


def test_messages_cannot_drive_the_terminal(tmp_path, capsys):
    """What bgr prints quotes its input (file names, box ids): a control character there is
    written as its escape, so that a file cannot clear, retitle or rewrite the user's terminal."""
    doc = boxes_doc(ESCAPES, None)
    doc["root"]["children"][1]["id"] = ESCAPES  # two boxes with that id: an error naming it
    (tmp_path / "dup.json").write_text(json.dumps(doc))
    code, err = run(["retarget", tmp_path / "dup.json", "--size", "10,10,10"], capsys)
    assert code == 1 and "two boxes have the id" in err, err
    assert "\\x1b[2J" in err
    source = tmp_path / f"city{ESCAPES[:-2]}.obj"  # a file name (no NUL)
    source.write_text(obj_text("box"))
    code, err = run(["infer", source, "-o", tmp_path / f"out{ESCAPES[:-2]}.bgr"], capsys)
    assert code == 0 and "\\x1b]0;owned\\x07\\r" in err, err
    for printed in (err, run(["infer", source, "--kind", "boxes"], capsys)[1]):
        assert not any(c in printed for c in "\x1b\x07\r\x00\u202e"), repr(printed)


def test_messages_cut_what_they_quote(tmp_path, capsys):
    """A 100,000-character id or label is legal input, but an error quoting it whole buried
    the message (the long fuzz run kept only its last 4,000 characters): it is cut."""
    doc = boxes_doc(LONG, None)
    doc["root"]["children"][1]["id"] = LONG
    (tmp_path / "dup.json").write_text(json.dumps(doc))
    code, err = run(["retarget", tmp_path / "dup.json", "--size", "10,10,10"], capsys)
    assert code == 1 and "two boxes have the id 'xxx" in err and len(err) < 1000, err[:300]
    model = json.loads((EXAMPLES / "captured" / "corner_shop.json").read_text())
    model["labels"][LONG + "!"] = {"fixed": True}
    (tmp_path / "m.json").write_text(json.dumps(model))
    code, err = run(["infer", tmp_path / "m.json", "--kind", "schema"], capsys)
    assert code == 1 and "not a valid label" in err and len(err) < 1000, err[:300]
