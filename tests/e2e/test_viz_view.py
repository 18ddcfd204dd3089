"""The 3D view read from its pixels, as a person sees it: a live TurtleBot run in the office
(the turtlebot_stanley exercise, with its planner and goals, and a node that rolls ahead at
0.1 m/s: the reference drives out of the first frame within seconds, before a loaded machine has
taken two screenshots), viser's page opened through the proxy in Chromium's software WebGL at
1400x850. In the default view the robot covers a clearly visible area in its
body colour, that colour stands out from the ring of pixels around it (WCAG contrast ratio), and
the robot moves between two screenshots; the panel shows the run's time and state. Screenshots
land in test-artifacts/screenshots/ (viz-*.png)."""

from __future__ import annotations

import colorsys
import io
import time

import numpy as np
import pytest
from PIL import Image
from playwright.sync_api import expect
from scipy import ndimage

from server.exercises.grading import reference_nodes
from server.exercises.registry import get_exercise
from server.viz.robot_drawing import BODY_RGB
from tests.viz.conftest import TURTLEBOT_ROLL

pytestmark = pytest.mark.slow  # Chromium drives the pages: seconds per test

VIEWPORT = {"width": 1400, "height": 850}
MIN_ROBOT_PX = 5_000  # [px] the floor for "clearly visible" at 1400x850
MIN_CONTRAST = 3.0  # [-] WCAG 2 contrast ratio of the robot against its surroundings
HUE_TOLERANCE = 0.06  # [1 turn] ~22 degrees: shading changes value, not hue
MIN_SATURATION = 0.35  # [-] floor, walls and map are greys; the robot's colour is not
RING_INNER_PX, RING_OUTER_PX = 3, 12  # [px] the ring around the robot: past its anti-aliased rim
PANEL_PADDING_PX = 30  # [px] viser's panel reaches this far left of its buttons
AXES_PX = 90  # [px] the axes widget's corner
MIN_MOVE_PX = 3.0  # [px] the robot's centroid between two screenshots of the running robot


def relative_luminance(rgb: np.ndarray) -> np.ndarray:
    """WCAG 2's relative luminance of sRGB colours (..., 3) in 0-255."""
    c = rgb.astype(np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    return linear @ np.array([0.2126, 0.7152, 0.0722])


def robot_mask(image: np.ndarray, body_rgb: tuple[int, int, int], covered=()) -> np.ndarray:
    """The largest connected patch of pixels with the body colour's hue (any shade of it),
    outside the `covered` boxes."""
    hsv = np.asarray(Image.fromarray(image).convert("HSV"), dtype=np.float64) / 255.0
    body_hue = colorsys.rgb_to_hsv(*(v / 255.0 for v in body_rgb))[0]
    distance = np.abs(hsv[..., 0] - body_hue)
    distance = np.minimum(distance, 1.0 - distance)
    candidates = (distance < HUE_TOLERANCE) & (hsv[..., 1] >= MIN_SATURATION) & (hsv[..., 2] > 0.1)
    for x, y, width, height in covered:
        candidates[int(y) : int(y + height) + 1, int(x) : int(x + width) + 1] = False
    labels, count = ndimage.label(candidates)
    if count == 0:
        return candidates
    sizes = ndimage.sum(candidates, labels, range(1, count + 1))
    return labels == 1 + int(np.argmax(sizes))


def measure(png: bytes, body_rgb: tuple[int, int, int], covered=()) -> dict:
    """Robot pixels, their centroid and the contrast ratio of their median luminance against
    the median of the ring around them. `covered`: boxes (x, y, width, height) [px] of the page
    over the 3D canvas (viser's panel, its axes widget), whose blue is not the robot's."""
    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    mask = robot_mask(image, body_rgb, covered)
    pixels = int(mask.sum())
    if pixels == 0:
        return {"pixels": 0, "contrast": 0.0, "centroid": (float("nan"), float("nan"))}
    ring = ndimage.binary_dilation(mask, iterations=RING_OUTER_PX) & ~ndimage.binary_dilation(
        mask, iterations=RING_INNER_PX
    )
    luminance = relative_luminance(image)
    robot_l, ring_l = float(np.median(luminance[mask])), float(np.median(luminance[ring]))
    lighter, darker = max(robot_l, ring_l), min(robot_l, ring_l)
    rows, cols = np.nonzero(mask)
    return {
        "pixels": pixels,
        "contrast": (lighter + 0.05) / (darker + 0.05),
        "centroid": (float(cols.mean()), float(rows.mean())),
    }


def test_measure_finds_a_disc_and_its_contrast() -> None:
    """The measurement itself: a blue disc on grey is found whole, with its contrast."""
    image = np.full((200, 300, 3), 200, dtype=np.uint8)
    yy, xx = np.mgrid[:200, :300]
    image[(xx - 150) ** 2 + (yy - 100) ** 2 < 40**2] = BODY_RGB
    image[10:20, 10:20] = BODY_RGB  # a smaller patch of the same colour is not the robot
    buffer = io.BytesIO()
    Image.fromarray(image).save(buffer, format="PNG")
    found = measure(buffer.getvalue(), BODY_RGB)
    assert abs(found["pixels"] - np.pi * 40**2) < 200
    assert found["centroid"] == (150.0, 100.0)
    expected = (relative_luminance(np.array([200, 200, 200])) + 0.05) / (
        relative_luminance(np.array(BODY_RGB)) + 0.05
    )
    assert abs(found["contrast"] - expected) < 1e-6


def covered_boxes(page) -> list[tuple[float, float, float, float]]:
    """What lies over the 3D canvas: viser's panel (from its left edge, found by a button in
    it, to the right of the page) and the axes widget in the bottom-left corner."""
    width, height = VIEWPORT["width"], VIEWPORT["height"]
    button = page.get_by_role("button", name="Frame world").bounding_box()
    panel_left = button["x"] - PANEL_PADDING_PX
    return [(panel_left, 0, width - panel_left, height), (0, height - AXES_PX, AXES_PX, AXES_PX)]


def _screenshot_when(page, path, predicate, timeout_s: float, what: str) -> dict:
    """Screenshots (the last kept at `path`) until `predicate(measured)` holds: the scene
    arrives over a websocket and renders in software, so poll, never sleep a fixed time."""
    deadline = time.monotonic() + timeout_s
    covered = covered_boxes(page)
    while True:
        png = page.screenshot(path=str(path))
        measured = measure(png, BODY_RGB, covered)
        if predicate(measured):
            return measured
        assert time.monotonic() < deadline, f"{what}: last measured {measured}"
        page.wait_for_timeout(100)


def test_the_robot_reads_at_a_glance_and_moves(web_lab, new_page, screenshots) -> None:
    exercise = get_exercise("turtlebot_stanley")
    (node,) = reference_nodes(exercise)  # its name; the code rolls slowly ahead instead
    student = web_lab.student("viewer")
    started = student.post(
        "/api/runs",
        json={"exercise": exercise.id, "clock": "realtime", "duration": 40,
              "nodes": [{"name": node.name, "code": TURTLEBOT_ROLL}]},
    )  # fmt: skip
    assert started.status_code == 201, started.text
    run_id = started.json()["id"]
    try:
        page = new_page(VIEWPORT["width"], VIEWPORT["height"])
        page.context.add_cookies(
            [{"name": c.name, "value": c.value, "url": web_lab.url} for c in student.cookies.jar]
        )
        page.goto(f"{web_lab.url}/api/runs/{run_id}/viz/")
        expect(page.locator("canvas").first).to_be_visible(timeout=20_000)
        expect(page.get_by_text("running")).to_be_visible(timeout=20_000)
        first = _screenshot_when(
            page,
            screenshots / "viz-live-1.png",
            lambda m: m["pixels"] >= MIN_ROBOT_PX,
            30.0,
            "the robot never drew large",
        )
        second = _screenshot_when(
            page,
            screenshots / "viz-live-2.png",
            lambda m: (
                m["pixels"] >= MIN_ROBOT_PX
                and np.hypot(*np.subtract(m["centroid"], first["centroid"])) >= MIN_MOVE_PX
            ),
            20.0,
            "the robot did not move on screen",
        )
        expect(page.get_by_text("t = ")).to_be_visible()
        moved_px = np.hypot(*np.subtract(second["centroid"], first["centroid"]))
        print(
            f"robot {first['pixels']} px, contrast {first['contrast']:.2f}:1; then "
            f"{second['pixels']} px, {second['contrast']:.2f}:1, moved {moved_px:.1f} px"
        )
        for measured in (first, second):
            assert measured["pixels"] >= MIN_ROBOT_PX, measured
            assert measured["contrast"] >= MIN_CONTRAST, measured
    finally:
        student.post(f"/api/runs/{run_id}/stop")
