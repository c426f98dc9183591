"""The textured surfaces of bench/fuzz_inverse.py (issue 26): seeds and mutations of CityGML 2.0,
OBJ+MTL with an image, and textured glTF/GLB, each run as ``bgr render FILE -o out.png``.

A textured model is several files (a CityGML file and its images, an OBJ, its MTL and an image,
a glTF, its .bin and an image), and any of them may be hostile, so a case mutates one file of
the seed, drawn by :func:`mutate_case`: the model itself (the generic byte and number
mutations, and ones that know its format), or a file beside it.

* CityGML: a DOCTYPE with entities, undeclared prefixes, a 1 MB attribute, elements nested 300
  to 20,000 deep, an ``app:imageURI`` out of the folder, at /dev/zero, absolute, a URL or 100,000
  characters, texture coordinates of NaN, 1e308 or repeated 100,000 times, a posList of odd
  length, a gml:id given to two elements, targets and rings that name nothing, hostile
  ``srsName``, ``srsDimension``, ``wrapMode``, colours and transparency.
* OBJ+MTL: ``vt`` of NaN and 1e308, face texture indices past the ``vt``, ``mtllib`` elsewhere;
  ``map_Kd`` out of the folder, at /dev/zero, 100,000 characters, a NUL, hostile options.
* glTF/GLB: the image's ``uri``, ``bufferView`` and ``mimeType``, the sampler's values, the
  texture's source, a material's texture index and ``texCoord``, ``KHR_texture_transform`` of
  NaN, the TEXCOORD_0 accessor's count, type, component type and offset, the image's
  bufferView; in a GLB the image bytes inside the BIN chunk.
* Images (PNG, PLATEAU's JPEGs): truncated, bytes changed, a header claiming 100,000 x 100,000
  or 12,000 x 12,000 pixels (checksum kept right, so the header reads), a real 1-bit PNG of
  12,000 x 12,000 pixels (18 KB; 432 MB decoded), not an image at all.

Seeds are made when the run starts and never committed: a hand-written CityGML wall and roof
(a ParameterizedTexture and an X3DMaterial, one file in EPSG:6697 and one in EPSG:6677), slices
of the PLATEAU file in ../shared/data/textured (one or two buildings with the appearance targets
that name their surfaces, and the images those use), a textured OBJ+MTL box, and the GLB and
glTF that bgr derives from a grammar with setupProjection/projectUV/texture.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import random
import re
import struct
import zlib
from collections.abc import Callable
from pathlib import Path

import fuzz_mutations as fm

ROOT = Path(__file__).resolve().parent.parent
PLATEAU = ROOT.parent / "shared" / "data" / "textured" / "plateau_tokyo"
PLATEAU_FILE = "53392633_bldg_6697_2_op.gml"
SURFACES = ("citygml", "obj-mtl", "gltf-tex")
SIZE = (64, 48)  # the rendered image of a case
# a mutant is cut to this size: the CityGML reader reads about 3 MB/s (expat, then Python per
# element and per polygon), so a 23 MB mutant (a building repeated 200 times, then a block
# 1,000 times) took 8 s alone and over 10 s beside other work; a faster reader is to do
MAX_MUTANT = 10_000_000


def command(name: str) -> list[str]:
    """The bgr command of a textured case, run in the case's folder."""
    return ["render", name, "-o", "out.png", "--size", f"{SIZE[0]}x{SIZE[1]}",
            "--backend", "numpy"]  # fmt: skip


# ---------------------------------------------------------------- seeds


def png(width: int, height: int, phase: int = 0) -> bytes:
    """A small generated RGB PNG: brick-like rows of two colours (numpy, Pillow)."""
    import numpy as np
    from PIL import Image

    y, x = np.mgrid[0:height, 0:width]
    brick = ((y // 2 + phase) % 2 == 0) ^ (((x + 2 * (y // 2 % 2)) // 4) % 2 == 0)
    rgb = np.where(brick[..., None], (180, 70, 50), (235, 225, 200)).astype(np.uint8)
    out = io.BytesIO()
    Image.fromarray(rgb).save(out, format="PNG")
    return out.getvalue()


def _bomb_png() -> bytes:
    """A valid 1-bit PNG of 12,000 x 12,000 pixels: 18 KB on disk, 432 MB as RGB."""
    from PIL import Image

    out = io.BytesIO()
    Image.new("1", (12_000, 12_000)).save(out, format="PNG")
    return out.getvalue()


CITYGML = """<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0"
 xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml"
 xmlns:app="http://www.opengis.net/citygml/appearance/2.0"
 xmlns:xlink="http://www.w3.org/1999/xlink">
 <gml:boundedBy><gml:Envelope srsName="{srs}" srsDimension="3">
  <gml:lowerCorner>{lo}</gml:lowerCorner><gml:upperCorner>{hi}</gml:upperCorner>
 </gml:Envelope></gml:boundedBy>
 <core:cityObjectMember><bldg:Building gml:id="B1">
  <bldg:boundedBy><bldg:WallSurface gml:id="W1"><bldg:lod2MultiSurface><gml:MultiSurface>
   <gml:surfaceMember><gml:Polygon gml:id="P1"><gml:exterior><gml:LinearRing gml:id="R1">
    <gml:posList srsDimension="3">{wall}</gml:posList>
   </gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
  </gml:MultiSurface></bldg:lod2MultiSurface></bldg:WallSurface></bldg:boundedBy>
  <bldg:boundedBy><bldg:RoofSurface gml:id="S1"><bldg:lod2MultiSurface><gml:MultiSurface>
   <gml:surfaceMember><gml:Polygon gml:id="P2"><gml:exterior><gml:LinearRing gml:id="R2">
    <gml:posList srsDimension="3">{roof}</gml:posList>
   </gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>
  </gml:MultiSurface></bldg:lod2MultiSurface></bldg:RoofSurface></bldg:boundedBy>
 </bldg:Building></core:cityObjectMember>
 <app:appearanceMember><app:Appearance><app:theme>rgbTexture</app:theme>
  <app:surfaceDataMember><app:ParameterizedTexture>
   <app:imageURI>tex/wall.png</app:imageURI><app:mimeType>image/png</app:mimeType>
   <app:wrapMode>wrap</app:wrapMode>
   <app:target uri="#P1"><app:TexCoordList>
    <app:textureCoordinates ring="#R1">0 0 2 0 2 1.5 0 1.5 0 0</app:textureCoordinates>
   </app:TexCoordList></app:target>
  </app:ParameterizedTexture></app:surfaceDataMember>
  <app:surfaceDataMember><app:X3DMaterial gml:id="M1">
   <app:diffuseColor>0.6 0.3 0.2</app:diffuseColor><app:transparency>0</app:transparency>
   <app:target>#P2</app:target>
  </app:X3DMaterial></app:surfaceDataMember>
 </app:Appearance></app:appearanceMember>
</core:CityModel>
"""


def _citygml(srs: str, origin: tuple[float, float], step: tuple[float, float]) -> bytes:
    """The hand-written wall (4 units along x, 3 m high) and roof (4 x 2) at ``origin``,
    horizontal units of ``step`` (metres, or degrees for a geographic CRS: lat, lon)."""
    a, b = origin
    da, db = step

    def ring(points):
        return " ".join(f"{a + da * p:.9f} {b + db * q:.9f} {z:g}" for p, q, z in points)

    wall = ring([(0, 0, 0), (4, 0, 0), (4, 0, 3), (0, 0, 3), (0, 0, 0)])
    roof = ring([(0, 0, 3), (4, 0, 3), (4, -2, 3), (0, -2, 3), (0, 0, 3)])
    lo, hi = f"{a:.9f} {b - 2 * db:.9f} 0", f"{a + 4 * da:.9f} {b:.9f} 3"
    return CITYGML.format(srs=srs, lo=lo, hi=hi, wall=wall, roof=roof).encode()


_MEMBER = re.compile(r"<core:cityObjectMember>.*?</core:cityObjectMember>", re.S)
_URI_TARGET = re.compile(r'<app:target uri="#?([^"]*)">.*?</app:target>\s*', re.S)
_TEXT_TARGET = re.compile(r"<app:target>#?([^<]*)</app:target>\s*")
_DATA_MEMBER = re.compile(r"<app:surfaceDataMember>.*?</app:surfaceDataMember>\s*", re.S)


def plateau_slice(members: list[int]) -> tuple[bytes, dict[str, bytes]] | None:
    """Buildings ``members`` of the PLATEAU file, with the appearance targets that name their
    surfaces and the images those use (None when the shared data is absent)."""
    path = PLATEAU / PLATEAU_FILE
    if not path.is_file():
        return None
    text = path.read_text(encoding="utf-8")
    found = _MEMBER.findall(text)
    kept = [found[i] for i in members]
    ids = set(re.findall(r'gml:id="([^"]+)"', "".join(kept)))
    start = text.index("<app:appearanceMember>")
    end = text.rindex("</app:appearanceMember>") + len("</app:appearanceMember>")
    appearance = _URI_TARGET.sub(lambda m: m.group(0) if m.group(1) in ids else "", text[start:end])
    appearance = _TEXT_TARGET.sub(lambda m: m.group(0) if m.group(1) in ids else "", appearance)
    appearance = _DATA_MEMBER.sub(
        lambda m: m.group(0) if "<app:target" in m.group(0) else "", appearance
    )
    head = text[: text.index("<core:cityObjectMember>")]
    body = head + "\n".join(kept) + "\n" + appearance + "\n</core:CityModel>\n"
    extra = {}
    for uri in set(re.findall(r"<app:imageURI>([^<]+)</app:imageURI>", appearance)):
        extra[uri] = (PLATEAU / uri).read_bytes()
    return body.encode(), extra


OBJ = """# a textured box: brick walls (u along the wall, 1 per metre), a plain roof
mtllib model.mtl
v 0 0 0\nv 4 0 0\nv 4 0 -3\nv 0 0 -3\nv 0 5 0\nv 4 5 0\nv 4 5 -3\nv 0 5 -3
vt 0 0\nvt 4 0\nvt 4 5\nvt 0 5\nvt 3 0\nvt 3 5\nvt 0.5 0.5
vn 0 0 1\nvn 1 0 0\nvn 0 0 -1\nvn -1 0 0\nvn 0 1 0
o box
usemtl brick
f 1/1/1 2/2/1 6/3/1 5/4/1
f 2/1/2 3/5/2 7/6/2 6/4/2
f 3/1/3 4/2/3 8/3/3 7/4/3
f 4/1/4 1/5/4 5/6/4 8/4/4
usemtl plain
f 5/7/5 6/7/5 7/7/5 8/7/5
"""
MTL = """newmtl brick
Kd 1 1 1
map_Kd tex/brick.png
newmtl plain
Kd 0.6 0.3 0.2
d 1
"""
GRAMMAR = """Lot --> extrude(6) Mass
Mass --> comp(f) { side: Wall | top: Roof }
Wall --> setupProjection(0, scope.xy, '1, '1) projectUV(0) texture("t.png")
Roof --> color("#884433")
"""


def _derived_textured(tmp: Path, fmt: str) -> dict[str, bytes]:
    """The files bgr derives from GRAMMAR (beside a generated t.png) as ``model.FMT``."""
    from bgr.cli import main

    folder = tmp / f"textured-{fmt}"
    folder.mkdir()
    (folder / "t.png").write_bytes(png(16, 16))
    (folder / "t.bgr").write_text(GRAMMAR)
    target = folder / f"model.{fmt}"
    with contextlib.redirect_stderr(io.StringIO()):
        status = main(["derive", str(folder / "t.bgr"), "-o", str(target)])
    if status != 0:
        raise SystemExit(f"cannot derive the textured seed as {fmt}")
    return {"main": target.read_bytes()}


def _external_gltf(gltf: bytes, image: bytes) -> tuple[bytes, dict[str, bytes]]:
    """The derived .gltf with its buffer in model.bin and its image a t.png beside it."""
    doc = json.loads(gltf)
    data = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    doc["buffers"][0]["uri"] = "model.bin"
    doc["images"] = [{"uri": "t.png", "mimeType": "image/png"}]
    return json.dumps(doc).encode(), {"model.bin": data, "t.png": image}


def build_seeds(tmp: Path, seed_type: Callable) -> dict[str, list]:
    """The seeds of the textured surfaces (``seed_type``: fuzz_inverse.Seed)."""
    seeds: dict[str, list] = {s: [] for s in SURFACES}
    wall = {"tex/wall.png": png(8, 8)}
    seeds["citygml"] += [
        seed_type("citygml", "wall_6697.gml",
                  _citygml("EPSG:6697", (35.6812, 139.7671), (9e-6, -1.8e-5)), wall),
        seed_type("citygml", "wall_6677.gml",
                  _citygml("EPSG:6677", (-35000.0, -6000.0), (1.0, 1.0)), wall),
    ]  # fmt: skip
    for name, members in (("plateau_first.gml", [0]), ("plateau_two.gml", [4, 9])):
        sliced = plateau_slice(members)
        if sliced is not None:
            seeds["citygml"].append(seed_type("citygml", name, *sliced))
    image = png(16, 16, 1)
    seeds["obj-mtl"].append(
        seed_type("obj-mtl", "model.obj", OBJ.encode(),
                  {"model.mtl": MTL.encode(), "tex/brick.png": image})
    )  # fmt: skip
    seeds["obj-mtl"].append(
        seed_type("obj-mtl", "quads.obj", OBJ.replace("model.mtl", "quads.mtl").encode(),
                  {"quads.mtl": MTL.replace("tex/brick.png", "brick.jpg").encode(),
                   "brick.jpg": _jpeg(image)})
    )  # fmt: skip
    glb = _derived_textured(tmp, "glb")["main"]
    gltf = _derived_textured(tmp, "gltf")["main"]
    seeds["gltf-tex"].append(seed_type("gltf-tex", "model.glb", glb, {}))
    seeds["gltf-tex"].append(seed_type("gltf-tex", "model.gltf", gltf, {}))
    seeds["gltf-tex"].append(seed_type("gltf-tex", "external.gltf", *_external_gltf(gltf, image)))
    return seeds


def _jpeg(png_bytes: bytes) -> bytes:
    from PIL import Image

    out = io.BytesIO()
    with Image.open(io.BytesIO(png_bytes)) as im:
        im.convert("RGB").save(out, format="JPEG", quality=90)
    return out.getvalue()


# ---------------------------------------------------------------- XML (CityGML)

HOSTILE_URIS = (
    "../../../../etc/passwd", "/etc/passwd", "/dev/zero", "/proc/self/mem", "/dev/stdin",
    "file:///dev/zero", "http://example.com/a.png", "%2e%2e/%2e%2e/etc/passwd", "tex", ".", "",
    "tex/../../outside.png", "missing.png", "a" * 100_000, "C:\\textures\\a.png", "tex/wall.png ",
    "data:image/png;base64,iVBORw0KGgo=", "\\\\server\\share\\a.png", "tex//wall.png", "é💥.png",
)  # fmt: skip
HOSTILE_COORDS = (
    "nan nan nan nan", "1e308 1e308 -1e308 1e308 0 0 1e308 0", "inf 0 0 inf 0 0 -inf 0",
    "0 0 1", "", "0", "1e400 0 0 1 1 1 0 0", "x y z w", "0 0 1 0 1 1 0 1 0 0 0.5",
    "-1e9 1e9 1e9 -1e9 0 0 1e9 1e9 5 5",
)  # fmt: skip
DOCTYPES = (
    '<!DOCTYPE a [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;">]>\n',
    '<!DOCTYPE a [<!ENTITY xxe SYSTEM "file:///etc/passwd">]>\n',
    '<!DOCTYPE a SYSTEM "http://example.com/a.dtd">\n',
    "<!DOCTYPE a>\n",
)


def _text_of(rng: random.Random, text: str, tag: str) -> re.Match | None:
    found = list(re.finditer(rf"(<[\w.-]*:?{tag}\b[^>]*>)([^<]*)(</)", text))
    return rng.choice(found) if found else None


def _replace_text(rng: random.Random, text: str, tag: str, values) -> str:
    m = _text_of(rng, text, tag)
    if m is None:
        return text
    new = values(m.group(2)) if callable(values) else rng.choice(values)
    return text[: m.start(2)] + new + text[m.end(2) :]


def _numbers(rng: random.Random, old: str) -> str:
    """A hostile list of numbers for a posList or textureCoordinates."""
    words = old.split()
    roll = rng.random()
    if roll < 0.3:
        return rng.choice(HOSTILE_COORDS)
    if roll < 0.5 and words:  # odd length: a number dropped
        del words[rng.randrange(len(words))]
    elif roll < 0.65:  # huge counts
        words = words * rng.choice((1000, 100_000))
    elif words:
        for _ in range(rng.choice((1, 3))):
            words[rng.randrange(len(words))] = rng.choice(fm.HOSTILE_NUMBERS)
    return " ".join(words)


def mutate_xml(rng: random.Random, data: bytes) -> bytes:
    """One CityGML-aware change (see the module)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return fm.mutate_bytes(rng, data)
    roll = rng.randrange(14)
    if roll == 0:  # a DOCTYPE (entities, external ones)
        at = text.find("?>") + 2 if text.startswith("<?xml") else 0
        text = text[:at] + "\n" + rng.choice(DOCTYPES) + text[at:]
    elif roll == 1:  # an undeclared prefix on an element (open and close) or an attribute
        m = rng.choice(list(re.finditer(r"<([\w.-]+):([\w.-]+)", text)) or [None])
        if m is not None:
            prefix = rng.choice(("zz", "xAL", "uro", "", "a:b"))
            text = re.sub(rf"(</?){m.group(1)}:{m.group(2)}\b",
                          lambda k: f"{k.group(1)}{prefix + ':' if prefix else ''}{m.group(2)}",
                          text)  # fmt: skip
        text = text.replace("<gml:Polygon ", '<gml:Polygon q:x="1" ', 1)
    elif roll == 2:  # a huge attribute
        at = text.find("<", text.find("<core:cityObjectMember") + 1)
        size = rng.choice((100_000, 1_000_000))
        text = text[: at + 1] + text[at + 1 :].replace(">", f' huge="{"a" * size}">', 1)
    elif roll == 3:  # deep nesting
        depth = rng.choice((255, 300, 5000, 20_000))
        at = text.find("<app:surfaceDataMember>")
        at = at if at >= 0 else text.find("<core:cityObjectMember>")
        tag = rng.choice(("a", "gml:MultiSurface", "app:target"))
        text = text[:at] + f"<{tag}>" * depth + f"</{tag}>" * depth + text[at:]
    elif roll == 4:  # an image path out of the folder, at a device, absolute, a URL, huge
        text = _replace_text(rng, text, "imageURI", HOSTILE_URIS)
    elif roll == 5:  # texture coordinates of NaN, 1e308, odd or huge counts
        text = _replace_text(rng, text, "textureCoordinates", lambda old: _numbers(rng, old))
    elif roll == 6:  # a posList of odd length, NaN, huge counts
        text = _replace_text(rng, text, "posList", lambda old: _numbers(rng, old))
    elif roll == 7:  # a gml:id given to another element too
        ids = re.findall(r'gml:id="([^"]+)"', text)
        if len(ids) >= 2:
            a, b = rng.sample(ids, 2)
            text = text.replace(f'gml:id="{b}"', f'gml:id="{a}"', 1)
    elif roll == 8:  # targets and rings that name nothing (or everything)
        new = rng.choice(("#nothing", "", "#", "nothing", "#" + "x" * 100_000, "#B1"))
        text = re.sub(r'(uri|ring)="[^"]*"', lambda m: f'{m.group(1)}="{new}"', text,
                      count=rng.choice((1, 0)))  # fmt: skip
        text = re.sub(r"<app:target>[^<]*<", f"<app:target>{new}<", text, count=1)
    elif roll == 9:  # hostile CRS
        srs = rng.choice(("EPSG:4326", "EPSG:4978", "EPSG:6697", "EPSG:999999", "", "x" * 10_000,
                          "urn:ogc:def:crs:EPSG::6697", "EPSG:6677", "+proj=geocent",
                          "http://www.opengis.net/def/crs/EPSG/0/3857"))  # fmt: skip
        text = re.sub(r'srsName="[^"]*"', f'srsName="{srs}"', text, count=1)
    elif roll == 10:
        dim = rng.choice(("2", "4", "0", "-1", "nan", "99999999999", "x"))
        text = re.sub(r'srsDimension="[^"]*"', f'srsDimension="{dim}"', text,
                      count=rng.choice((1, 0)))  # fmt: skip
    elif roll == 11:  # wrap modes, colours, transparency, themes
        tag = rng.choice(("wrapMode", "diffuseColor", "transparency", "theme", "mimeType"))
        values = ("nan nan nan", "1e400 0 0", "-1 2 0.5", "1", "", "border", "mirror", "clamp",
                  "x" * 100_000, "inf", "image/gif")  # fmt: skip
        text = _replace_text(rng, text, tag, values)
    elif roll == 12:  # a building member repeated
        m = rng.choice(list(_MEMBER.finditer(text)) or [None])
        if m is not None:
            text = text[: m.end()] + m.group(0) * rng.choice((2, 50, 200)) + text[m.end() :]
    else:  # an element's text replaced by markup that does not belong there
        tag = rng.choice(("posList", "imageURI", "textureCoordinates"))
        markup = ("<gml:Polygon/>", "&amp;&lt;", "&#0;", "&undefined;", "]]>")
        text = _replace_text(rng, text, tag, markup)
    return text.encode("utf-8", "surrogatepass")


# ---------------------------------------------------------------- OBJ and MTL

HOSTILE_MAPS = (
    *HOSTILE_URIS[:16], "brick.png\x00.txt", "-s 1 1 1", "-o nan nan nan tex/brick.png",
    "-bm 1e308 tex/brick.png", "-clamp on tex/brick.png", "-s", "tex/brick.png extra",
)  # fmt: skip


def mutate_obj_tex(rng: random.Random, data: bytes) -> bytes:
    """OBJ: a ``vt`` made hostile, a face's texture index past the ``vt``, ``mtllib`` moved."""
    lines = data.split(b"\n")
    roll = rng.random()
    vts = [i for i, line in enumerate(lines) if line.startswith(b"vt ")]
    faces = [i for i, line in enumerate(lines) if line.startswith(b"f ")]
    if roll < 0.35 and vts:
        i = rng.choice(vts)
        lines[i] = b"vt " + b" ".join(rng.choice(fm.HOSTILE_NUMBERS).encode() for _ in range(2))
    elif roll < 0.65 and faces:
        i = rng.choice(faces)
        fields = lines[i].split(b" ")
        k = rng.randrange(1, len(fields))
        parts = fields[k].split(b"/")
        bad = rng.choice(fm.HOSTILE_NUMBERS[11:22] + ("", "99", "x")).encode()
        fields[k] = b"/".join([parts[0], bad, *parts[2:]])
        lines[i] = b" ".join(fields)
    else:
        lib = rng.choice(HOSTILE_MAPS + ("model.mtl model.mtl", "quads.mtl\nmtllib quads.mtl"))
        lines = [b"mtllib " + lib.encode("utf-8", "surrogatepass") if ln.startswith(b"mtllib")
                 else ln for ln in lines]  # fmt: skip
    return b"\n".join(lines)


def mutate_mtl(rng: random.Random, data: bytes) -> bytes:
    """MTL: ``map_Kd`` out of the folder, at a device, huge, NUL, hostile options; Kd and d."""
    lines = data.split(b"\n")
    roll = rng.random()
    if roll < 0.6:
        new = rng.choice(HOSTILE_MAPS).encode("utf-8", "surrogatepass")
        lines = [b"map_Kd " + new if ln.startswith(b"map_Kd") else ln for ln in lines]
    elif roll < 0.8:
        word = rng.choice((b"Kd", b"d", b"Tr", b"newmtl", b"map_d", b"map_Bump"))
        value = rng.choice((b"nan nan nan", b"1e308 -1e308 0", b"", b"x" * 100_000, b"\x00",
                            b"tex/brick.png", b"brick", b"-1"))  # fmt: skip
        lines.insert(rng.randrange(len(lines) + 1), word + b" " + value)
    else:
        return fm.mutate_lines(rng, data)
    return b"\n".join(lines)


# ---------------------------------------------------------------- images

_BOMB: list[bytes] = []


def _png_chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


def mutate_image(rng: random.Random, data: bytes) -> bytes:
    """A PNG or JPEG made hostile: truncated, bytes changed, lying dimensions, a bomb."""
    roll = rng.random()
    if roll < 0.3:
        return data[: rng.randrange(max(1, len(data)))]
    if roll < 0.5:
        return fm.mutate_bytes(rng, data)
    if roll < 0.8:
        width, height = rng.choice(((100_000, 100_000), (12_000, 12_000), (65_535, 1),
                                    (1, 2**31 - 1), (0, 0), (20_000, 5_000)))  # fmt: skip
        if data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR":
            body = struct.pack(">II", width, height) + data[24:29]
            return data[:8] + _png_chunk(b"IHDR", body) + data[33:]
        m = re.search(rb"\xff[\xc0\xc2]", data)
        if m is not None:  # a JPEG's frame header: height then width, 16 bits each
            b = bytearray(data)
            struct.pack_into(">HH", b, m.start() + 5, min(height, 65535), min(width, 65535))
            return bytes(b)
        return fm.mutate_bytes(rng, data)
    if roll < 0.9:
        if not _BOMB:
            _BOMB.append(_bomb_png())
        return _BOMB[0]
    return rng.choice((b"", b"not an image", b"GIF89a" + b"\x00" * 20, b"\x89PNG\r\n\x1a\n"))


# ---------------------------------------------------------------- glTF

_ACCESSOR_VALUES = {
    "count": (0, 1, 2, 3000, 10**6, 2**31, -1, 1.5, None),
    "componentType": (5120, 5121, 5123, 5125, 5130, 0, "x"),
    "type": ("VEC3", "SCALAR", "MAT4", "vec2", 2),
    "byteOffset": (1, 3, 4096, -4, 2**40),
    "normalized": (True, "yes"),
    "bufferView": (0, 99, -1, None),
}
_SAMPLER_VALUES = (0, -1, 9728, 9987, 10497, 33071, 33648, 2**40, "x", None, 1e308)


def _gltf_tex_change(rng: random.Random, doc: dict) -> None:
    roll = rng.randrange(8)
    if roll == 0:  # the image's uri
        uris = (*HOSTILE_URIS, "data:image/png;base64,@@", "data:image/png;base64," + "A" * 400_000)
        doc["images"][0]["uri"] = rng.choice(uris)
        if rng.random() < 0.5:
            doc["images"][0].pop("bufferView", None)
    elif roll == 1:  # the image's bufferView and mimeType
        image = doc["images"][0]
        key = rng.choice(("bufferView", "mimeType"))
        image[key] = rng.choice(
            (1, 2, 99, -1, 1.5, "0", None, 2**63)
            if key == "bufferView"
            else ("image/gif", "", "text/html", 5, None, "image/jpeg")
        )
    elif roll == 2:  # the sampler
        sampler = doc["samplers"][0]
        for key in rng.sample(["wrapS", "wrapT", "magFilter", "minFilter"], rng.randint(1, 4)):
            sampler[key] = rng.choice(_SAMPLER_VALUES)
    elif roll == 3:  # the texture
        texture = doc["textures"][0]
        texture[rng.choice(("source", "sampler"))] = rng.choice((1, -1, 99, None, "0", 1.5))
    elif roll == 4:  # a material's texture reference
        refs = [m["pbrMetallicRoughness"]["baseColorTexture"] for m in doc["materials"]
                if "baseColorTexture" in m.get("pbrMetallicRoughness", {})]  # fmt: skip
        ref = rng.choice(refs)
        if rng.random() < 0.5:
            ref[rng.choice(("index", "texCoord"))] = rng.choice((1, 5, -1, 99, None, 2**40))
        else:
            transform = {
                "offset": [float("nan"), 1e308],
                "scale": rng.choice(([0, 0], [1e308, -1e308])),
                "rotation": rng.choice((float("inf"), 1e30)),
                "texCoord": rng.choice((0, 3)),
            }
            ref["extensions"] = {"KHR_texture_transform": transform}
    elif roll == 5:  # the TEXCOORD_0 accessor
        at = [p["attributes"]["TEXCOORD_0"] for m in doc["meshes"] for p in m["primitives"]
              if "TEXCOORD_0" in p.get("attributes", {})]  # fmt: skip
        accessor = doc["accessors"][rng.choice(at)]
        key = rng.choice(list(_ACCESSOR_VALUES))
        accessor[key] = rng.choice(_ACCESSOR_VALUES[key])
    elif roll == 6:  # the image's bufferView
        view = doc["bufferViews"][doc["images"][0].get("bufferView", 0)]
        view[rng.choice(("byteLength", "byteOffset", "buffer"))] = rng.choice(
            (0, 1, 8, 10**9, -1, 2**63, 1.5, 5)
        )
    else:  # TEXCOORD_0 given to an untextured primitive, or removed from the textured one
        prims = [p for m in doc["meshes"] for p in m["primitives"]]
        prim = rng.choice(prims)
        if "TEXCOORD_0" in prim["attributes"]:
            del prim["attributes"]["TEXCOORD_0"]
        else:
            prim["attributes"]["TEXCOORD_0"] = prim["attributes"]["POSITION"]
            prim["material"] = len(doc["materials"]) - 1


def mutate_gltf_tex(rng: random.Random, data: bytes) -> bytes:
    """A textured glTF's JSON (or a GLB's JSON chunk, lengths kept right) changed where it
    names its texture (see the module)."""
    if data[:4] == b"glTF" and len(data) >= 20:
        json_len = struct.unpack_from("<I", data, 12)[0]
        doc_bytes, rest = data[20 : 20 + json_len], data[20 + json_len :]
        if rng.random() < 0.3:
            return _glb_image_bytes(rng, data, doc_bytes, json_len)
        new = mutate_gltf_tex(rng, doc_bytes)
        new += b" " * (-len(new) % 4)
        body = struct.pack("<II", len(new), 0x4E4F534A) + new + rest
        return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body
    try:
        doc = json.loads(data)
        _gltf_tex_change(rng, doc)
    except fm.SHAPE_ERRORS:
        return fm.mutate_json(rng, data)
    return fm._dumps(doc)


def _glb_image_bytes(rng: random.Random, data: bytes, doc_bytes: bytes, json_len: int) -> bytes:
    """The image inside a GLB's BIN chunk mutated in place (its bufferView's length kept)."""
    try:
        doc = json.loads(doc_bytes)
        view = doc["bufferViews"][doc["images"][0]["bufferView"]]
        start = 20 + json_len + 8 + int(view.get("byteOffset", 0))
        length = int(view["byteLength"])
    except fm.SHAPE_ERRORS:
        return fm.mutate_bytes(rng, data)
    if not 0 <= start <= start + length <= len(data):  # a view an earlier mutation made lie:
        return fm.mutate_bytes(rng, data)  # padding to its length once asked for 10^18 bytes
    image = mutate_image(rng, data[start : start + length])[:length]
    image += b"\x00" * (length - len(image))
    return data[:start] + image + data[start + length :]


# ---------------------------------------------------------------- a case

MAIN = {
    "citygml": ((mutate_xml, 4), (fm.mutate_numbers, 2), (fm.mutate_mild, 1), (fm.mutate_bytes, 1)),
    "obj-mtl": (
        (mutate_obj_tex, 3),
        (fm.mutate_lines, 2),
        (fm.mutate_numbers, 1),
        (fm.mutate_mild, 1),
        (fm.mutate_bytes, 1),
    ),  # fmt: skip
    ".gltf": (
        (mutate_gltf_tex, 4),
        (fm.mutate_json, 2),
        (fm.mutate_gltf_uri, 1),
        (fm.mutate_numbers, 1),
        (fm.mutate_bytes, 1),
    ),  # fmt: skip
    ".glb": ((mutate_gltf_tex, 4), (fm.mutate_glb, 2), (fm.mutate_bytes, 1)),
    ".mtl": ((mutate_mtl, 3), (fm.mutate_bytes, 1)),
    ".png": ((mutate_image, 1),),
    ".jpg": ((mutate_image, 1),),
    ".bin": ((fm.mutate_bytes, 1),),
}


def _mutators(surface: str, name: str) -> tuple:
    suffix = Path(name).suffix.lower()
    return MAIN.get(suffix) or MAIN[surface]


def mutate_case(rng: random.Random, surface: str, name: str, data: bytes,
                extra: dict[str, bytes]) -> tuple[bytes, dict[str, bytes]]:  # fmt: skip
    """One to three mutations of one file of a textured seed: the model (two thirds of the
    cases) or a file beside it.  Returns the model's bytes and the files beside it."""
    extra = dict(extra)
    target = name
    if extra and rng.random() < 1 / 3:
        target = rng.choice(sorted(extra))
    content = data if target == name else extra[target]
    pairs = _mutators(surface, target)
    for _ in range(rng.choice((1, 1, 1, 2, 3))):
        mutator = rng.choices([m for m, _ in pairs], [w for _, w in pairs])[0]
        try:
            content = mutator(rng, content)
        except fm.SHAPE_ERRORS:
            content = fm.mutate_bytes(rng, content)
        content = content[:MAX_MUTANT]
    if target == name:
        return content, extra
    extra[target] = content
    return data, extra
