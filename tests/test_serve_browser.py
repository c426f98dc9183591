"""``bgr serve`` in a real headless Chromium (the Debian package ``chromium``, driven by
Playwright; issue 32): the page loads without console errors and shows the model, re-renders
within 2 s of a save, shows an error with its line for a broken save and recovers on the next
good one, re-derives when a slider moves, and names the terminal clicked.

Skipped where Playwright or a Chromium is missing.  ``BGR_SCREENSHOTS=FOLDER`` keeps the
screenshots (docs/images/serve-*.png were made so).
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

sync_api = pytest.importorskip("playwright.sync_api")
CHROMIUM = next(
    (p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None
)
pytestmark = [
    pytest.mark.skipif(CHROMIUM is None, reason="no Chromium (apt install chromium)"),
    pytest.mark.xdist_group("serve"),
]

HOUSE = """attr floors = 3
@Range(min = 4, max = 20)
attr width = 10
terminal Wall
Lot --> s(width, 0, 8) extrude(floors * 3) comp(f) { side: color("#c8b89a") Wall | top: Roof }
Roof --> roof(gable, 35) color("#8a4b3c")
"""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    folder = tmp_path_factory.mktemp("serve")
    grammar = folder / "house.bgr"
    grammar.write_text(HOUSE)
    port = free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "bgr", "serve", str(grammar), "--port", str(port)],
        stderr=subprocess.PIPE,
    )
    try:
        with sync_api.sync_playwright() as p:
            browser = p.chromium.launch(
                executable_path=CHROMIUM,
                args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"],
            )
            tab = browser.new_page(viewport={"width": 1000, "height": 650})
            tab.problems = []  # type: ignore[attr-defined]
            tab.on("console", lambda m: m.type == "error" and tab.problems.append(m.text))
            tab.on("pageerror", lambda e: tab.problems.append(str(e)))
            deadline = time.monotonic() + 30
            while True:
                try:
                    tab.goto(f"http://127.0.0.1:{port}/")
                    break
                except sync_api.Error:
                    if time.monotonic() > deadline:
                        raise
                    time.sleep(0.2)
            tab.grammar = grammar  # type: ignore[attr-defined]
            yield tab
            browser.close()
    finally:
        server.terminate()
        server.wait(10)


def version(tab) -> int:
    return int(tab.evaluate("document.body.dataset.version"))


def shot(tab, name: str) -> bytes:
    image = tab.screenshot()
    keep = os.environ.get("BGR_SCREENSHOTS")
    if keep:
        Path(keep, f"serve-{name}.png").write_bytes(image)
    return image


def test_the_page_shows_the_model_without_console_errors(page):
    page.wait_for_function("document.body.dataset.version !== '0'", timeout=30_000)
    page.wait_for_timeout(500)
    import io

    from PIL import Image

    pixels = np.asarray(Image.open(io.BytesIO(shot(page, "model"))).convert("RGB"), float)
    height, width = pixels.shape[:2]
    view = pixels[:, : width - 320]  # the model's side of the page
    centre = view[height // 3 : 2 * height // 3, view.shape[1] // 3 : 2 * view.shape[1] // 3]
    background = np.array([0xF2, 0xF2, 0xF2])
    assert np.abs(centre - background).sum(axis=2).mean() > 30  # the building, not the backdrop
    assert page.problems == []


def test_a_save_re_renders_within_two_seconds(page):
    page.wait_for_function("document.body.dataset.version !== '0'", timeout=30_000)
    before = version(page)
    page.grammar.write_text(HOUSE.replace("floors = 3", "floors = 5"))
    start = time.monotonic()
    page.wait_for_function(f"Number(document.body.dataset.version) > {before}", timeout=10_000)
    assert time.monotonic() - start < 2.0
    assert page.problems == []


def test_a_broken_save_shows_its_line_and_the_next_good_one_recovers(page):
    page.wait_for_function("document.body.dataset.version !== '0'", timeout=30_000)
    page.grammar.write_text(HOUSE.replace("extrude(floors * 3)", "extrude(floors * )"))
    page.wait_for_function("document.body.dataset.state === 'error'", timeout=10_000)
    text = page.inner_text("#error-text")
    assert "house.bgr:5:" in text and "^" in text
    shot(page, "error")
    before = version(page)
    page.grammar.write_text(HOUSE)
    page.wait_for_function(f"Number(document.body.dataset.version) > {before}", timeout=10_000)
    assert page.is_hidden("#error")


def test_a_slider_re_derives_and_a_click_names_the_terminal(page):
    page.wait_for_function("document.body.dataset.version !== '0'", timeout=30_000)
    before = version(page)
    slider = page.locator("input[name=width]")
    slider.fill("16")  # moves the range input and fires its input event
    page.wait_for_function(f"Number(document.body.dataset.version) > {before}", timeout=10_000)
    page.wait_for_timeout(300)
    box = page.locator("#view canvas").bounding_box()
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.wait_for_function(
        "document.getElementById('picked').textContent.includes('Lot')", timeout=5_000
    )
    assert page.inner_text("#picked").split("\n")[0] in ("Wall", "Roof")
    shot(page, "picked")
