"""Values that enter from outside (issue 10, "Hostile inputs"): the Python API's arguments,
``--set``/``--lot``/``--seed``/``--size`` on the command line, camera files, and a few language
corners (line endings, randint, face(), non-finite numbers, huge strings).  Each bad value is one
located BgrError (or a usage error, status 2), never an internal error; GeoJSON files are in
test_footprints.py and test_fuzz_geojson.py."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

import bgr
from bgr.cli import main

BOX = 'attr height = 10\nattr style = "brick"\nterminal X\nLot --> extrude(height) X\n'


@pytest.fixture(scope="module")
def box():
    return bgr.load(BOX)


def heights(result) -> list[float]:
    return [round(float(s[1]), 9) for s in result.terminals.size]


# ---------------------------------------------------------------------------------------------
# the Python API


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"lot": (1,)}, "lot must be (width, depth)"),
        ({"lot": 5}, "lot must be (width, depth)"),
        ({"lot": [1, 2, 3]}, "lot must be (width, depth)"),
        ({"lot": [None]}, "lot must be (width, depth)"),
        ({"lot": (True, 3)}, "lot must be (width, depth)"),
        ({"lot": []}, "empty list"),
        ({"lot": (float("nan"), 3)}, "over 0 and at most 1e8 metres"),
        ({"lot": (1e308, 1e308)}, "over 0 and at most 1e8 metres"),
        ({"lot": (10**400, 5)}, "over 0 and at most 1e8 metres"),
        ({"lot": (0, 5)}, "over 0"),
        ({"lot": (-3, 5)}, "over 0"),
        ({"lot": "nonexistent.geojson"}, "no such lot file"),
        ({"lot": "nan,3"}, "write the lot as WIDTH,DEPTH"),
        ({"lot": "1_0,3"}, "write the lot as WIDTH,DEPTH"),
        ({"attrs": {"height": 10**400}}, "out of range (at most 1e9 in size)"),
        ({"attrs": {"height": 1e300}}, "out of range (at most 1e9"),
        ({"attrs": {"height": float("nan")}}, "not a finite number"),
        ({"attrs": {"height": float("inf")}}, "not a finite number"),
        ({"attrs": {"height": [1]}}, "not a number, true/false or a string"),
        ({"attrs": {"height": None}}, "not a number, true/false or a string"),
        ({"attrs": {3: 4}}, "attr names must be strings"),
        ({"attrs": [1]}, "attrs must be a dict"),
        ({"attrs": "height=3"}, "attrs must be a dict"),
        ({"seed": "3"}, "the seed must be a whole number"),
        ({"seed": 1.5}, "the seed must be a whole number"),
        ({"seed": True}, "the seed must be a whole number"),
        ({"seed": 2**64}, "from -2**63 to 2**64 - 1"),
        ({"seed": 10**5000}, "too large to show"),
        ({"max_shapes": 0}, "max_shapes must be a positive whole number"),
        ({"max_shapes": 1.5}, "max_shapes must be a positive whole number"),
        ({"max_shapes": "5"}, "max_shapes must be a positive whole number"),
        ({"max_depth": None}, "max_depth must be a positive whole number"),
        ({"max_depth": -1}, "max_depth must be a positive whole number"),
    ],
)
def test_a_bad_argument_to_derive_is_a_bgr_error(box, kwargs, message):
    with pytest.raises(bgr.BgrError, match=re.escape(message)):
        bgr.derive(box, **kwargs)


def test_good_arguments_still_derive(box):
    import numpy as np

    assert heights(bgr.derive(box, attrs={"height": np.float64(4)}, lot=(np.int64(3), 4))) == [4]
    assert heights(bgr.derive(box, seed=-1, attrs={"height": 10**9}, lot=[3.5, 1e7])) == [1e9]
    assert len(bgr.derive(box, seed=2**64 - 1, lot="3,4")) == 1


@pytest.mark.parametrize("function", [bgr.format_source, bgr.parse, bgr.load])
@pytest.mark.parametrize("value", [None, 5, ["terminal X"]])
def test_text_of_the_wrong_python_type_is_a_clear_type_error(function, value):
    """Documented (bgr/__init__.py, docs/cli.md): a programmer's error, not a user's."""
    with pytest.raises(TypeError, match=f"takes .* not {type(value).__name__}"):
        function(value)


# ---------------------------------------------------------------------------------------------
# the command line


@pytest.fixture
def grammar(tmp_path):
    path = tmp_path / "box.bgr"
    path.write_text(BOX)
    return path


@pytest.mark.parametrize(
    "option, status, message",
    [
        ("--set=height=nan", 1, "--set height=nan: nan is not a finite number"),
        ("--set=height=inf", 1, "--set height=inf: inf is not a finite number"),
        ("--set=height=-Infinity", 1, "is not a finite number"),
        ("--set=height=1e400", 1, "--set height=1e400: 1e400 is not a finite number"),
        ("--set=height=1e300", 1, "out of range (at most 1e9"),
        ("--lot=1e308,1e308", 1, "--lot 1e+308,1e+308: a lot needs a width and depth over 0"),
        ("--lot=nan,3", 1, "--lot nan,3: write the lot as WIDTH,DEPTH"),
        ("--lot=0,5", 1, "--lot 0,5: a lot needs"),
        ("--lot=-3,5", 1, "--lot -3,5: a lot needs"),
        ("--seed=99999999999999999999999", 1, "the seed must be a whole number from"),
        pytest.param("--seed=1" + "0" * 5000, 2, "is not a whole number", id="5000 digits"),
        ("--seed=١٠", 2, "argument --seed: '١٠' is not a whole number"),
        ("--seed=1_0", 2, "argument --seed: '1_0' is not a whole number"),
        ("--max-shapes=1.5", 2, "argument --max-shapes: '1.5' is not a whole number"),
        ("--max-depth=0", 2, "must be positive"),
    ],
)
def test_a_bad_value_on_the_command_line_is_one_message(
    grammar, tmp_path, capsys, option, status, message
):
    try:
        code = main(["derive", str(grammar), "-o", str(tmp_path / "out.json"), option])
    except SystemExit as exit:  # argparse's usage errors
        code = exit.code
    err = capsys.readouterr().err
    assert code == status
    assert message in err and "Traceback" not in err and "internal error" not in err
    assert not (tmp_path / "out.json").exists()


@pytest.mark.parametrize("text", ["1_000", "١٠", "12 m", "0x10"])
def test_set_takes_only_the_language_number_syntax(grammar, tmp_path, capsys, text):
    """What is not a .bgr number is a string, as before: here a runtime error where it is used."""
    code = main(["derive", str(grammar), "-o", str(tmp_path / "o.json"), f"--set=height={text}"])
    assert code == 1
    assert f"extrude() needs a finite number, got '{text}'" in capsys.readouterr().err


@pytest.mark.parametrize("text, value", [("12", 12), ("-3.5", -3.5), ("1e3", 1000.0)])
def test_set_numbers(grammar, tmp_path, text, value):
    out = tmp_path / "o.json"
    assert main(["derive", str(grammar), "-o", str(out), f"--set=height={text}"]) == 0
    assert json.loads(out.read_text())["attrs"]["height"] == value


# ---------------------------------------------------------------------------------------------
# camera files and --size


@pytest.mark.parametrize(
    "camera, message",
    [
        ({"position": [0, 5, -30], "size": [100000, 100000]}, "1 to 8192 each"),
        ({"position": [0, 5, -30], "size": [8192, 8192]}, "at most 16,777,216 pixels in all"),
        ({"position": [0, 5, -30], "size": [0, 10]}, "two positive whole numbers"),
        ({"position": [0, 5, -30], "size": [10.5, 10]}, "two positive whole numbers"),
        ({"position": [0, 5, 1e300]}, "'position' must be a list of 3 numbers"),
        ({"position": [0, 5, 10**400]}, "'position' must be a list of 3 numbers"),
        ({"position": [0, 5, -30], "yaw": 10**400}, "'yaw' must be a number"),
        ({"position": [0, 5, -30], "fov": 1e300}, "'fov' must be a number"),
        ({"position": [0, 5, -30], "principal_point": [1e300, 0]}, "'principal_point'"),
    ],
)
def test_camera_file_values_are_range_checked(tmp_path, capsys, camera, message):
    grammar = tmp_path / "box.bgr"
    grammar.write_text(BOX)
    cam = tmp_path / "cam.json"
    cam.write_text(json.dumps(camera))
    out = tmp_path / "out.png"
    code = main(["render", str(grammar), "-o", str(out), "--view", str(cam), "--backend", "numpy"])
    err = capsys.readouterr().err
    assert code == 1 and message in err and "internal error" not in err
    assert err.startswith(f"{cam}: error: ")
    assert not out.exists()


@pytest.mark.parametrize("size", ["100000x100000", "8192x8192", "0x10", "²x3", "١٠x10", "12"])
def test_render_size_option_is_range_checked(tmp_path, capsys, size):
    grammar = tmp_path / "box.bgr"
    grammar.write_text(BOX)
    code = main(["render", str(grammar), "-o", str(tmp_path / "o.png"), "--size", size])
    err = capsys.readouterr().err
    assert code == 2 and f"--size {size}: write WIDTHxHEIGHT" in err


def test_camera_objects_refuse_a_size_too_large():
    from bgr.render.camera import Camera

    with pytest.raises(bgr.BgrError, match="too large"):
        Camera.from_angles(0, 0, 0, (0, 0, -10), size=(100000, 100000))


# ---------------------------------------------------------------------------------------------
# the language: line endings, randint, face(), non-finite numbers, long strings


def test_a_lone_carriage_return_ends_a_line_for_check_and_derive(tmp_path, capsys):
    path = tmp_path / "cr.bgr"
    path.write_bytes(b"attr h = 10\r// a comment\rterminal X\rLot --> extrude(h) X Y\r")
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:4:22: error: unknown rule 'Y'")
    assert "    4 | Lot --> extrude(h) X Y\n" in err
    path.write_bytes(b"attr h = 10\r// a comment\rterminal X\rLot --> extrude(h) X\r")
    assert main(["check", str(path)]) == 0
    assert heights(bgr.derive(bgr.load(path))) == [10.0]
    mixed = "attr h = 10\r\n// c\rterminal X\nLot --> extrude(h) X Y\r\n"
    with pytest.raises(bgr.BgrError) as caught:
        bgr.load(mixed)
    assert caught.value.line == 4


@pytest.mark.parametrize(
    "expression, message",
    [
        ("randint(0.5, 0.7)", "randint(0.5, 0.7): no whole number lies between them"),
        ("randint(3, 2)", "randint(3, 2): no whole number lies between them"),
        ("randint(1e308 * 10, 1)", "needs finite bounds"),
        ("randint(1e308 * 10 - 1e308 * 10, 1)", "needs finite bounds"),
    ],
)
def test_randint_needs_a_whole_number_between_its_bounds(expression, message):
    source = f"attr n = {expression}\nterminal X\nLot --> extrude(n) X\n"
    with pytest.raises(bgr.BgrError, match=re.escape(message)) as e:
        bgr.derive(source)
    assert (e.value.line, e.value.column) == (1, 10)


def test_randint_draws_the_whole_numbers_between_its_bounds():
    source = "terminal X\nLot --> split(x) { ~1: extrude(randint(0.5, 3.2)) X }*\n"
    result = bgr.derive(source, lot=(400, 10))
    assert set(heights(result)) == {1.0, 2.0, 3.0}


@pytest.mark.parametrize(
    "index, message",
    [
        ("0.5", "face() needs a whole number, got 0.5"),
        ("1e308 * 10", "face() needs a whole number, got inf"),
        ('"a"', 'face() needs a whole number, got the string "a"'),
        ("true", "face() needs a whole number, got True"),
    ],
)
def test_a_face_index_must_be_whole(index, message):
    source = f"terminal X\nLot --> extrude(3) comp(f) {{ face({index}): X }}\n"
    with pytest.raises(bgr.BgrError, match=re.escape(message)) as e:
        bgr.derive(source)
    assert (e.value.line, e.value.column) == (2, 30)
    assert len(bgr.derive(source.replace(f"face({index})", "face(2.0)"))) == 1


@pytest.mark.parametrize(
    "body, message",
    [
        ("(BIG - BIG)%: X | else: X", "a percentage must be a number from 0 to 100, got nan"),
        ("(BIG)%: X | else: X", "the percentages add up to inf%"),
        ("split(x) { ~(BIG - BIG): X | ~1: X }", "a split size must be a finite number"),
        ("split(x) { ~BIG: X | ~1: X }", "a split size must be a finite number"),
        ("split(x) { (BIG - BIG): X }*", "a split size must be a finite number"),
        ("extrude(1e400) X", "number 1e400 is too large"),
    ],
)
def test_no_non_finite_number_reaches_a_size_or_a_percentage(body, message):
    """An overflow (BIG is inf) is refused where it is used; a const or attr that overflows is
    refused where it is declared."""
    source = f"terminal X\nLot --> {body.replace('BIG', '(1e308 * 10)')}\n"
    with pytest.raises(bgr.BgrError, match=re.escape(message)) as e:
        bgr.derive(source)
    assert e.value.line == 2


def test_numbers_in_the_language_are_ascii():
    with pytest.raises(bgr.BgrError, match="unexpected"):
        bgr.load("terminal X\nLot --> extrude(١٠) X\n")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
def test_a_long_string_literal_is_refused_cheaply():
    script = (
        "import bgr\n"
        "text = 'terminal X\\nattr s = \"' + 'a' * 10_000_000 + '\"\\nLot --> X\\n'\n"
        "try:\n"
        "    bgr.load(text)\n"
        "except bgr.BgrError as e:\n"
        "    print(e.render())\n"
        # VmHWM, not ru_maxrss: ru_maxrss keeps the forking pytest's peak across exec
        "print(open('/proc/self/status').read().split('VmHWM:')[1].split()[0])\n"
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    *message, peak_kb = done.stdout.splitlines()
    assert message[0] == "<text>:2:10: error: a string of 10,000,000 characters is too long " + (
        "(at most 65,536)"
    )
    assert len(message[1]) < 200  # the source line is cut around the caret
    assert int(peak_kb) < 400_000  # it was 3.4 GB


def test_a_string_of_the_limit_is_fine():
    assert bgr.load(f'attr s = "{"a" * 65_536}"\nterminal X\nLot --> X\n')


def test_a_carriage_return_in_a_string_is_written_escaped():
    """A raw CR ends a line, so the formatter writes one inside a string as the escape \\r."""
    source = 'attr a = "x\\ry"\n'
    assert bgr.format_source(source) == source
    (attr,) = bgr.parse(source).items
    assert attr.value.value == "x\ry"
