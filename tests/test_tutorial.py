"""The notebook tutorial, ``examples/tutorial.ipynb``: it runs top to bottom on a fresh
kernel (nbclient), prints what a student checks, draws its figures, and its embedded
meshcat animation plays in Chromium from the saved output, showing the arm where
Pinocchio puts it. The notebook is committed without outputs, cell for cell the same as
its jupytext twin ``examples/tutorial.py``.
"""

from __future__ import annotations

import base64
import io
import re
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from browser import network_requests, require_chromium, scene_js, screenshot, start_chromium
from docs_build import NOTEBOOK, SCRIPT, executed_tutorial

from twolink_pin import SimulationConfig, default_trajectory, load_robot, make_scenario, simulate
from twolink_pin.kinematics import joint_positions

LINK2_LIFT = np.array([0.0, 0.0, 0.035])  # link 2's box axis above the plane in twolink.urdf [m]


def _cells(path: Path) -> list[tuple[str, str]]:
    import jupytext

    return [(c.cell_type, c.source.strip()) for c in jupytext.read(path).cells]


def test_notebook_and_its_script_have_the_same_cells() -> None:
    """tutorial.ipynb and tutorial.py (jupytext percent format) hold the same cells, in order:
    ``jupytext --sync`` was run after the last edit of either."""
    assert _cells(NOTEBOOK) == _cells(SCRIPT)


def test_committed_notebook_has_no_outputs() -> None:
    """Outputs are made by running it (tests, the site build), never committed."""
    import nbformat

    notebook = nbformat.read(NOTEBOOK, as_version=4)
    code = [c for c in notebook.cells if c.cell_type == "code"]
    assert len(code) >= 6
    assert [c.outputs for c in code] == [[]] * len(code)
    assert [c.execution_count for c in code] == [None] * len(code)
    assert notebook.metadata.kernelspec.name == "python3"


def _texts(cell: Any) -> str:
    parts = []
    for output in cell.outputs:
        if output.output_type == "stream":
            parts.append(output.text)
        elif "text/plain" in output.get("data", {}):
            parts.append(output.data["text/plain"])
    return "".join(parts)


def _html_outputs() -> list[str]:
    return [
        o.data["text/html"]
        for c in executed_tutorial().notebook.cells
        if c.cell_type == "code"
        for o in c.outputs
        if "text/html" in o.get("data", {})
    ]


def test_tutorial_runs_top_to_bottom_on_a_fresh_kernel() -> None:
    """Every code cell ran, in order, with no error (nbclient stops a cell after its timeout); the cells print
    p = (3.4, 0.4, 0.3), M and C equal to the closed form within 1e-12, a feasible
    trajectory and the two laws' RMS errors."""
    executed = executed_tutorial()
    code = [c for c in executed.notebook.cells if c.cell_type == "code"]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1))
    assert not [o for c in code for o in c.outputs if o.output_type == "error"]
    text = "".join(_texts(c) for c in code)
    assert "p = [3.4 0.4 0.3] kg·m²" in text
    worst = [float(x) for x in re.findall(r"largest \|[MC]_pinocchio - [MC]_report\| = (\S+)", text)]
    assert len(worst) == 2 and max(worst) < 1e-12
    assert "FEASIBLE: peak" in text and "NOT FEASIBLE" not in text
    assert re.search(r"pd: RMS e = \[0\.0\d+ 0\.0\d+\] rad", text)
    assert re.search(r"adaptive: RMS e = \[0\.0\d+ 0\.0\d+\] rad", text)


def test_tutorial_draws_its_figures() -> None:
    """Two matplotlib figures (the reference, the tracking errors), as PNG outputs that
    decode to pictures of several hundred pixels with real content."""
    import matplotlib.image

    pngs = [
        base64.b64decode(o.data["image/png"])
        for c in executed_tutorial().notebook.cells
        if c.cell_type == "code"
        for o in c.outputs
        if "image/png" in o.get("data", {})
    ]
    assert len(pngs) == 2
    for png in pngs:
        image = np.asarray(matplotlib.image.imread(io.BytesIO(png), format="png"))
        assert image.shape[0] > 250 and image.shape[1] > 700, image.shape
        assert image[..., :3].std() > 0.05


def test_animation_output_is_one_self_contained_iframe() -> None:
    """The 3-D cell's output is one ``<iframe srcdoc>`` whose (escaped) page inlines the
    viewer and the scene: no ``src=`` to fetch and no unescaped quote ending the attribute."""
    (html,) = _html_outputs()
    match = re.fullmatch(r'<iframe class="twolink-pin-animation" [^>]*srcdoc="([^"]*)"></iframe>', html)
    assert match, html[:300]
    assert " src=" not in html.split("srcdoc=", 1)[0]
    assert "MeshCat.Viewer" in match[1] and "window.sceneLoaded = true;" in match[1]
    assert 0.5e6 < len(html) < 4e6


@pytest.fixture(scope="module")
def animation_frame(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """Chromium on a page holding the notebook's saved animation output, switched into
    its frame once the scene has loaded; with the URLs requested meanwhile."""
    require_chromium()
    (html,) = _html_outputs()
    page = tmp_path_factory.mktemp("notebook") / "output.html"
    page.write_text(f'<!DOCTYPE html><html><body style="margin:0">{html}</body></html>', encoding="utf-8")
    with start_chromium(900, 500) as driver:
        driver.execute_cdp_cmd(
            "Emulation.setDeviceMetricsOverride",
            {"width": 900, "height": 500, "deviceScaleFactor": 1, "mobile": False},
        )
        network_requests(driver)
        driver.get(page.as_uri())
        driver.switch_to.frame(driver.find_element("css selector", "iframe.twolink-pin-animation"))
        deadline = time.monotonic() + 30
        while not driver.execute_script("return window.sceneLoaded === true;"):
            assert time.monotonic() < deadline, "the embedded scene never loaded"
            time.sleep(0.1)
        scene_js(driver, "viewer.animator.play(); viewer.animator.pause();")
        yield driver, network_requests(driver)


@pytest.mark.browser
def test_embedded_animation_shows_the_arm_where_pinocchio_puts_it(animation_frame: Any) -> None:
    """In the saved output, the scene holds the arm and its translucent ghost; seeking the
    animation puts the end of link 2 at the end effector of Pinocchio's FK of the adaptive
    run the notebook made (the same 8-s run, recomputed here), within 1 µm, and the ghost
    at the desired one; the page requested nothing from the network."""
    driver, requests = animation_frame
    assert [u for u in requests if not u.startswith(("file:", "data:", "about:"))] == []
    names = scene_js(
        driver,
        "var out = {}; for (var root of ['arm', 'ghost']) { var v = node(['meshcat', root, 'visuals']).children;"
        " out[root] = Object.keys(v).sort(); } return out;",
    )
    assert names["arm"] == names["ghost"] and "link2_0" in names["arm"] and len(names["arm"]) == 6
    assert scene_js(driver, "return viewer.animator.duration;") == pytest.approx(8.0, abs=1e-5)
    robot = load_robot()
    controller, plant = make_scenario("adaptive", robot)
    result = simulate(controller, plant, default_trajectory(robot), SimulationConfig(duration=8.0))
    for seek in (0.0, 0.48, 2.0, 6.4):
        k = int(np.searchsorted(result.t, seek - 1e-9))
        ee, ee_des = joint_positions(robot, np.array([result.q[k], result.q_des[k]]))[:, -1]
        arm, ghost = scene_js(
            driver, "seek(arguments[0]); return [link2End('arm'), link2End('ghost')];", seek
        )
        np.testing.assert_allclose(arm, ee + LINK2_LIFT, rtol=0, atol=1e-6)
        np.testing.assert_allclose(ghost, ee_des + LINK2_LIFT, rtol=0, atol=1e-6)


@pytest.mark.browser
def test_embedded_animation_is_drawn(animation_frame: Any) -> None:
    """The frame's canvas shows the links' blue and orange (the arm is drawn, not only in
    the scene tree)."""
    driver, _ = animation_frame
    scene_js(driver, "seek(1.0);")
    driver.execute_async_script(
        "var done = arguments[0]; viewer.set_dirty();"
        "requestAnimationFrame(function () { requestAnimationFrame(function () { done(); }); });"
    )
    image = screenshot(driver)[:, :, :3]  # the whole window, whichever frame the driver is in
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    blue = int(((b > 0.55) & (r < 0.4) & (b - r > 0.3)).sum())
    orange = int(((r > 0.7) & (g > 0.3) & (g < 0.7) & (b < 0.35)).sum())
    assert blue > 1000 and orange > 500, (blue, orange)
