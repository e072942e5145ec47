"""Tests of twolink_pin.visualization.overlays: the external force drawn as an arrow while it
acts, and the desired end-effector frame as a triad, read back from the page in Chromium.

The motion is a 2-s PD run of the twolink starting off the reference; a force
F = (12, −8, 0) N acts on the end effector over [0.5, 1.2) s (the plant's window
convention: the sample at 0.5 s carries it, the one at 1.2 s does not). Positions read
from the page are mapped back to our frame with ``viewer.scene.worldToLocal``; expected
ones come from Pinocchio's forward kinematics of the same ``q`` and ``q_des``.
"""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from browser import require_chromium, start_chromium
from browser import scene_js as js

from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import load_robot
from twolink_pin.run_spec import make_scenario
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.trajectory import default_trajectory
from twolink_pin.visualization import write_html

ROBOT = load_robot()
FORCE = np.array([12.0, -8.0, 0.0])  # [N]
WINDOW = (0.5, 1.2)  # [s]
INSIDE = (0.6, 1.0, 1.16)  # whole frames at 25 fps, inside the window [s]
OUTSIDE = (0.0, 0.24, 1.24, 1.6, 2.0)


def _run() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    controller, plant = make_scenario("pd", ROBOT)
    result = simulate(controller, plant, default_trajectory(ROBOT), SimulationConfig(duration=2.0))
    return result.t, result.q, result.q_des


RUN = _run()


def _wrench(t: np.ndarray) -> np.ndarray:
    acting = (t >= WINDOW[0] - 1e-12) & (t < WINDOW[1] - 1e-12)
    return np.where(acting[:, None], FORCE, 0.0)


def _pose(q: np.ndarray) -> pin.SE3:
    """The end effector's world pose at ``q`` (Pinocchio)."""
    data = ROBOT.model.createData()
    pin.framesForwardKinematics(ROBOT.model, data, q)
    return data.oMf[ROBOT.ee_frame_id]


def _at(t: np.ndarray, x: np.ndarray, tk: float) -> np.ndarray:
    k = int(np.argmin(np.abs(t - tk)))
    assert abs(t[k] - tk) < 1e-9
    return x[k]


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    require_chromium()
    t, q, q_des = RUN
    path = write_html(
        ROBOT,
        t,
        q,
        q_des,
        path=tmp_path_factory.mktemp("overlays") / "wrench.html",
        fps=25.0,
        wrench=_wrench(t),
        desired_frame=True,
    )
    with start_chromium(800, 500) as driver:
        driver.get(Path(path).as_uri())
        deadline = time.monotonic() + 60
        while not driver.execute_script("return window.sceneLoaded === true;"):
            assert time.monotonic() < deadline, "the scene never arrived"
            time.sleep(0.1)
        js(driver, "viewer.animator.play(); viewer.animator.pause();")
        yield driver


def _legend_number(driver: Any, element: str) -> float:
    text = driver.execute_script(f"return document.getElementById('{element}').textContent;")
    match = re.search(r"(\d[\d.eE+-]*) m", text)
    assert match, text
    return float(match.group(1))


@pytest.mark.browser
def test_arrow_is_drawn_from_the_end_effector_along_the_force_only_while_it_acts(page: Any) -> None:
    """Inside the window the arrow is visible, starts at the end effector of q(t) and ends
    at F·s further (s the legend's scale, m per N); outside it is hidden."""
    t, q, _ = RUN
    scale = _legend_number(page, "wrench-scale")
    assert scale > 0
    for tk in INSIDE + OUTSIDE:
        visible, base, tip = js(
            page,
            "seek(arguments[0]); var o = node(['meshcat', 'wrench']).object;"
            "var shown = o.visible && o.parent.visible;"
            "return [shown, ours(o, [0, 0, 0]), ours(o, [1, 0, 0])];",
            tk,
        )
        if tk in INSIDE:
            assert visible, f"no arrow at t = {tk} s, inside the window"
            origin = _pose(_at(t, q, tk)).translation
            np.testing.assert_allclose(base, origin, rtol=0, atol=1e-5)
            np.testing.assert_allclose(np.subtract(tip, base), FORCE * scale, rtol=0, atol=1e-5)
        else:
            assert not visible, f"an arrow at t = {tk} s, outside the window"


@pytest.mark.browser
def test_triad_follows_the_desired_pose(page: Any) -> None:
    """At each time the triad's origin is the end effector of q_des(t) and its axes are that
    pose's rotation columns, each the legend's length."""
    t, _, q_des = RUN
    length = _legend_number(page, "axis-length")
    origins = []
    for tk in INSIDE + OUTSIDE:
        o, x, y, z = js(
            page,
            "seek(arguments[0]); var f = node(['meshcat', 'desired_frame']).object; var L = arguments[1];"
            "return [ours(f, [0, 0, 0]), ours(f, [L, 0, 0]), ours(f, [0, L, 0]), ours(f, [0, 0, L])];",
            tk,
            length,
        )
        pose = _pose(_at(t, q_des, tk))
        np.testing.assert_allclose(o, pose.translation, rtol=0, atol=1e-5)
        axes = np.column_stack([np.subtract(x, o), np.subtract(y, o), np.subtract(z, o)]) / length
        np.testing.assert_allclose(axes, pose.rotation, rtol=0, atol=1e-4)
        origins.append(o)
    assert np.ptp(np.array(origins), axis=0).max() > 0.05  # it really moves with the reference


def test_a_wrench_of_the_wrong_shape_is_refused_naming_it(tmp_path: Path) -> None:
    t, q, q_des = RUN
    with pytest.raises(InvalidParameterError, match=r"wrench\.shape"):
        write_html(ROBOT, t, q, q_des, path=tmp_path / "x.html", wrench=np.zeros((len(t), 2)))
    with pytest.raises(InvalidParameterError, match="wrench_frame"):
        write_html(ROBOT, t, q, q_des, path=tmp_path / "x.html", wrench=_wrench(t), wrench_frame="no_such")
    assert not (tmp_path / "x.html").exists()


def test_animate_draws_the_runs_wrench_and_the_desired_frame(tmp_path: Path) -> None:
    """``animate --wrench …`` draws the run's force (the legend states its scale) and the
    triad; without a wrench, the triad only."""
    from twolink_pin.cli import main

    with_wrench, without = tmp_path / "w.html", tmp_path / "n.html"
    run = ["animate", "pd", "--duration", "0.1"]
    assert main([*run, "--wrench", "10,0,0@0.02:0.06", "--html", str(with_wrench)]) == 0
    assert main([*run, "--html", str(without)]) == 0
    shown = with_wrench.read_text()
    assert 'id="wrench-scale">force arrow' in shown and 'id="axis-length">desired frame' in shown
    assert 'id="wrench-scale"' not in without.read_text() and 'id="axis-length"' in without.read_text()


def test_the_live_viewer_states_the_same_scale_as_the_page(tmp_path: Path) -> None:
    """serve draws the same arrow as write_html: its scale [m/N] (the live page has no legend)
    is the one the file's legend states, a round number that draws the largest force between
    0.12 and 0.3 of the motion's extent."""
    from twolink_pin.kinematics import joint_positions
    from twolink_pin.visualization import serve

    t, q, q_des = RUN
    page = write_html(ROBOT, t, q, q_des, path=tmp_path / "w.html", wrench=_wrench(t)).read_text()
    stated = float(re.search(r'id="wrench-scale">force arrow (\S+) m per N', page).group(1))  # type: ignore[union-attr]
    with serve(ROBOT, t, q, q_des, wrench=_wrench(t), quiet=True) as viewer:
        assert viewer.wrench_scale == stated
    points = np.vstack([joint_positions(ROBOT, x).reshape(-1, 3) for x in (q[::25], q_des[::25])])
    extent = float(np.ptp(points, axis=0).max())
    assert 0.12 * extent <= np.linalg.norm(FORCE) * stated <= 0.3 * extent + 1e-12
    with serve(ROBOT, t, q, q_des, quiet=True) as viewer:
        assert viewer.wrench_scale is None
