"""Tests of twolink_pin.visualization: what a person sees in the browser, for the exported
HTML file (opened from ``file://``) and for the live meshcat server.

The motion is a fake "tracked" run along the report's trajectory,
``q = q_des + 0.1·exp(−t)·(1, −1)`` [rad], so the arm and its ghost visibly differ early on.
Three.js draws our ``(x, y, z)`` as ``(x, z, −y)``: positions read from the page are mapped
back with ``(X, Y, Z) -> (X, −Z, Y)``.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from browser import network_requests, require_chromium, screenshot, start_chromium

from twolink_pin.errors import InvalidParameterError, OutputError
from twolink_pin.kinematics import forward_kinematics
from twolink_pin.model import RobotModel, load_robot
from twolink_pin.trajectory import REPORT_VIA_XY, build_trajectory
from twolink_pin.visualization import LiveViewer, ghost_visual_model, serve, visual_model, write_html

ROBOT: RobotModel = load_robot()
TRAJECTORY = build_trajectory(ROBOT)
DURATION = 4.0  # [s], one period of the report's trajectory
FPS = 25.0
SEEK_TIMES = (0.0, 0.48, 1.0, 2.0, 3.6, 4.0)  # whole frames [s]
LINK2_HEIGHT = 0.035  # link 2's box axis above the plane in twolink.urdf [m]


def fake_motion(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(q, q_des)`` [rad] at times ``t`` [s]: the report's trajectory and a decaying offset."""
    q_des = TRAJECTORY.sample(t).q
    return q_des + 0.1 * np.exp(-t)[:, None] * np.array([1.0, -1.0]), q_des


def sample_run(duration: float = DURATION, dt: float = 1e-3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.linspace(0.0, duration, round(duration / dt) + 1)
    return (t, *fake_motion(t))


# ----------------------------------------------------------------------------- no browser


@pytest.fixture(scope="module")
def html_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    t, q, q_des = sample_run()
    return write_html(
        ROBOT, t, q, q_des, path=tmp_path_factory.mktemp("html") / "run.html", via_xy=REPORT_VIA_XY, fps=FPS
    )


def test_thirty_second_run_fits_in_a_few_megabytes(tmp_path: Path) -> None:
    """A 30-s run sampled at 1 kHz exports (25 fps) to a single file under 5 MB."""
    t, q, q_des = sample_run(30.0)
    path = write_html(ROBOT, t, q, q_des, path=tmp_path / "run30.html", via_xy=REPORT_VIA_XY)
    assert path.stat().st_size < 5e6
    assert [p.name for p in tmp_path.iterdir()] == ["run30.html"]  # no temporary file left


BAD_INPUTS = [
    ("q", lambda t, q, qd: (t, q[:, :1], qd), r"q\.shape = \(4001, 1\) is invalid: expected \(4001, 2\)"),
    ("q_des", lambda t, q, qd: (t, q, qd[:-1]), r"q_des\.shape = \(4000, 2\) is invalid"),
    (
        "nan",
        lambda t, q, qd: (
            t,
            np.where(np.arange(2) == 1, np.where(np.arange(len(t))[:, None] == 7, np.nan, q), q),
            qd,
        ),
        r"q\[7, 1\] = nan is invalid: expected finite values \[rad\]",
    ),
    (
        "inf t",
        lambda t, q, qd: (np.where(np.arange(len(t)) == 3, np.inf, t), q, qd),
        r"t\[3\] = inf is invalid",
    ),
    (
        "t order",
        lambda t, q, qd: (np.where(np.arange(len(t)) == 5, t[3], t), q, qd),
        r"t\[5\] = 0\.003 is invalid: expected a time > t\[4\] = 0\.004 s",
    ),
    ("t 2-D", lambda t, q, qd: (t[:, None], q, qd), r"t\.shape = \(4001, 1\) is invalid"),
]


@pytest.mark.parametrize(("case", "mutate", "message"), BAD_INPUTS, ids=[b[0] for b in BAD_INPUTS])
def test_bad_arrays_are_rejected_naming_the_value(
    case: str, mutate: Any, message: str, tmp_path: Path
) -> None:
    """Shape mismatches, non-finite entries and non-increasing times raise
    InvalidParameterError naming the entry; nothing is written."""
    t, q, q_des = mutate(*sample_run())
    with pytest.raises(InvalidParameterError, match=message):
        write_html(ROBOT, t, q, q_des, path=tmp_path / "run.html")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"fps": 0.0}, r"fps = 0\.0 is invalid: expected a finite frame rate > 0"),
        ({"fps": math.nan}, r"fps = nan is invalid"),
        ({"via_xy": [(0.4, 0.1, 0.0)]}, r"via_xy\.shape = \(1, 3\) is invalid: expected \(M, 2\)"),
    ],
)
def test_bad_options_are_rejected(kwargs: dict[str, Any], message: str, tmp_path: Path) -> None:
    t, q, q_des = sample_run(0.2)
    with pytest.raises(InvalidParameterError, match=message):
        write_html(ROBOT, t, q, q_des, path=tmp_path / "run.html", **kwargs)


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An error while writing leaves the previous file untouched and no half file behind."""
    target = tmp_path / "run.html"
    target.write_text("previous")
    t, q, q_des = sample_run(0.2)

    def broken_fsync(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", broken_fsync)
    with pytest.raises(OSError, match="No space left"):
        write_html(ROBOT, t, q, q_des, path=target)
    assert target.read_text() == "previous"
    assert [p.name for p in tmp_path.iterdir()] == ["run.html"]


def test_directory_as_path_is_an_output_error(tmp_path: Path) -> None:
    t, q, q_des = sample_run(0.2)
    with pytest.raises(OutputError, match="is a directory"):
        write_html(ROBOT, t, q, q_des, path=tmp_path)


def test_ghost_is_a_translucent_copy() -> None:
    """The ghost has the same objects on the same joints, with alpha 0.3; the original is unchanged."""
    visual = visual_model(ROBOT)
    ghost = ghost_visual_model(visual, alpha=0.3)
    assert [g.name for g in ghost.geometryObjects] == [g.name for g in visual.geometryObjects]
    assert [g.parentJoint for g in ghost.geometryObjects] == [g.parentJoint for g in visual.geometryObjects]
    np.testing.assert_allclose([g.meshColor[3] for g in ghost.geometryObjects], 0.3, atol=1e-7)
    np.testing.assert_allclose([g.meshColor[3] for g in visual.geometryObjects], 1.0)
    with pytest.raises(InvalidParameterError, match=r"alpha = 0 is invalid: expected an opacity in \(0, 1\]"):
        ghost_visual_model(visual, alpha=0)


# ----------------------------------------------------------------------------- live server: binding


def _listening(port: int) -> list[str]:
    """Local addresses (hex, as in /proc/net/tcp*) of this process's sockets listening on ``port``."""
    inodes = set()
    for fd in Path("/proc/self/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    addresses = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not Path(table).exists():
            continue
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            address, hex_port = fields[1].rsplit(":", 1)
            if fields[3] == "0A" and int(hex_port, 16) == port and fields[9] in inodes:  # 0A: LISTEN
                addresses.append(address)
    return addresses


@pytest.fixture(scope="module")
def live_viewer() -> Iterator[LiveViewer]:
    t, q, q_des = sample_run()
    with serve(ROBOT, t, q, q_des, via_xy=REPORT_VIA_XY, fps=FPS, quiet=True) as viewer:
        yield viewer


def test_live_server_listens_on_loopback_only(live_viewer: LiveViewer) -> None:
    """Both the page/WebSocket socket and meshcat's ZMQ socket listen on 127.0.0.1, nowhere else."""
    zmq_port = int(live_viewer.zmq_url.rsplit(":", 1)[1])
    assert live_viewer.url == f"http://127.0.0.1:{live_viewer.port}/static/"
    assert _listening(live_viewer.port) == ["0100007F"]  # 127.0.0.1, little-endian hex
    assert _listening(zmq_port) == ["0100007F"]


def test_live_server_honours_host_and_closes_its_sockets() -> None:
    """``host`` is the one address listened on (127.0.0.2 here); ``close`` frees the ports."""
    t, q, q_des = sample_run(0.2)
    with serve(ROBOT, t, q, q_des, host="127.0.0.2", quiet=True) as viewer:
        port, zmq_port = viewer.port, int(viewer.zmq_url.rsplit(":", 1)[1])
        assert _listening(port) == ["0200007F"]
        assert _listening(zmq_port) == ["0100007F"]
    assert _listening(port) == [] and _listening(zmq_port) == []
    assert not viewer.running


# ----------------------------------------------------------------------------- in the browser

HELPERS = """
function node(path) {
  var n = viewer.scene_tree;
  for (var i = 0; i < path.length; i++) { n = n.children[path[i]]; if (n === undefined) return null; }
  return n;
}
function ours(object, local) {  // three.js world (x, z, -y) -> our (x, y, z)
  object.updateWorldMatrix(true, false);
  var v = object.localToWorld(object.position.clone().set(local[0], local[1], local[2]));
  return [v.x, -v.z, v.y];
}
function link2End(root) {
  var mesh = node(['meshcat', root, 'visuals', 'link2_0', '<object>']).object;
  return ours(mesh, [mesh.geometry.parameters.width / 2, 0, 0]);
}
function visibleTrail() {
  var pieces = node(['meshcat', 'trail']).children, shown = 0, total = 0;
  for (var k in pieces) { total += 1; if (pieces[k].object.visible) shown += 1; }
  return [shown, total];
}
function seek(t) { viewer.animator.pause(); viewer.animator.seek(t); }
"""


def js(driver: Any, body: str, *args: Any) -> Any:
    """Run ``body`` in the page with the helper functions above defined."""
    return driver.execute_script(HELPERS + body, *args)


@dataclass
class Page:
    driver: Any
    kind: str
    """``"file"`` or ``"live"``."""
    requests: list[str]
    """URLs the page requested while loading."""
    origin: str


@pytest.fixture(scope="module")
def chromium() -> Iterator[Any]:
    require_chromium()
    with start_chromium(800, 500) as driver:
        driver.execute_cdp_cmd(
            "Emulation.setDeviceMetricsOverride",
            {"width": 800, "height": 500, "deviceScaleFactor": 1, "mobile": False},
        )
        yield driver


@pytest.fixture(scope="module", params=["file", "live"])
def page(request: pytest.FixtureRequest, chromium: Any, html_file: Path) -> Page:
    """The scene loaded in Chromium, from the exported file or from the live server."""
    if request.param == "file":
        url, origin = html_file.as_uri(), "file://"
    else:
        viewer: LiveViewer = request.getfixturevalue("live_viewer")
        url, origin = viewer.url, f"http://127.0.0.1:{viewer.port}/"
    network_requests(chromium)  # drop earlier entries
    chromium.get(url)
    ready = (  # the live server sends the animation first, the via markers last
        "var v = node(['meshcat', 'via', '4', '<object>']);"
        "return !!(v && v.object.type === 'Mesh' && viewer.animator.actions.length > 0"
        " && node(['meshcat', 'ghost', 'visuals', 'link2_0', '<object>']));"
    )
    deadline = time.monotonic() + 30
    while not js(chromium, ready):
        assert time.monotonic() < deadline, f"the scene never arrived at {url}"
        time.sleep(0.1)
    js(chromium, "viewer.animator.play(); viewer.animator.pause();")  # actions active, clock stopped
    return Page(chromium, request.param, network_requests(chromium), origin)


@pytest.mark.browser
def test_page_requests_nothing_from_the_network(page: Page) -> None:
    """The exported file requests only file: and data: URLs; the live page only its own server."""
    assert page.requests, "no request recorded at all: the network log is not working"
    if page.kind == "file":
        allowed: tuple[str, ...] = ("file:", "data:")
    else:
        allowed = (page.origin, page.origin.replace("http:", "ws:"), "data:")
    assert [u for u in page.requests if not u.startswith(allowed)] == []


@pytest.mark.browser
def test_scene_holds_arm_ghost_paths_and_via_points(page: Page) -> None:
    """The three.js scene has the arm's five visuals, a translucent ghost of them, the trail,
    the desired path (a Line) and the five via markers; the animation lasts the run."""
    scene = js(
        page.driver,
        """
        function meshes(root) {
          var out = {}, visuals = node(['meshcat', root, 'visuals']).children;
          for (var name in visuals) { var o = visuals[name].children['<object>'].object;
            out[name] = [o.type, o.material.transparent, o.material.opacity]; }
          return out;
        }
        return {arm: meshes('arm'), ghost: meshes('ghost'),
                desired: node(['meshcat', 'desired_path', '<object>']).object.type,
                trail: visibleTrail()[1],
                via: Object.keys(node(['meshcat', 'via']).children).length,
                duration: viewer.animator.duration};
        """,
    )
    names = ["base_link_0", "ee_link_0", "link1_0", "link1_1", "link2_0", "link2_1"]
    assert sorted(scene["arm"]) == names and sorted(scene["ghost"]) == names
    assert all(v[0] == "Mesh" and not v[1] for v in scene["arm"].values())
    assert all(v[0] == "Mesh" and v[1] and abs(v[2] - 0.3) < 1e-6 for v in scene["ghost"].values())
    assert scene["desired"] == "Line"
    assert scene["trail"] >= 50
    assert scene["via"] == len(REPORT_VIA_XY)
    assert scene["duration"] == pytest.approx(DURATION, abs=1e-5)


@pytest.mark.browser
def test_seeking_puts_link2_end_where_pinocchio_fk_says(page: Page) -> None:
    """At several animation times the drawn end of link 2 is at FK(q(t)) and the ghost's at
    FK(q_des(t)), within 1 mm; the trail grows from nothing to complete."""
    t = np.array(SEEK_TIMES)
    q, q_des = fake_motion(t)
    shown = []
    for k, tk in enumerate(t):
        arm, ghost, trail = js(
            page.driver,
            "seek(arguments[0]); return [link2End('arm'), link2End('ghost'), visibleTrail()];",
            tk,
        )
        np.testing.assert_allclose(arm, [*forward_kinematics(ROBOT, q[k]), LINK2_HEIGHT], rtol=0, atol=1e-3)
        np.testing.assert_allclose(
            ghost, [*forward_kinematics(ROBOT, q_des[k]), LINK2_HEIGHT], rtol=0, atol=1e-3
        )
        shown.append(trail[0])
    assert shown[0] == 0 and shown[-1] == trail[1]
    assert shown == sorted(shown) and len(set(shown)) == len(shown)
    # the ghost really is elsewhere early on: 0.1 rad per joint ≈ 2 cm at the end effector
    assert np.linalg.norm(forward_kinematics(ROBOT, q[0]) - forward_kinematics(ROBOT, q_des[0])) > 0.01


def _frame(driver: Any) -> np.ndarray:
    """A screenshot after two animation frames have been drawn (RGB in [0, 1])."""
    driver.execute_async_script(
        "var done = arguments[0]; viewer.set_dirty();"
        "requestAnimationFrame(function () { requestAnimationFrame(function () { done(); }); });"
    )
    return screenshot(driver)[:, :, :3]


@pytest.mark.browser
def test_canvas_shows_arm_ghost_trail_and_via_points(page: Page) -> None:
    """The rendered picture has the links' blue and orange, the via points' red and the
    desired path's green; hiding the ghost or the trail changes it (they are drawn)."""
    js(page.driver, "seek(1.0);")
    image = _frame(page.driver)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    blue = (b > 0.55) & (r < 0.4) & (b - r > 0.3)
    orange = (r > 0.7) & (g > 0.3) & (g < 0.7) & (b < 0.35)
    red = (r > 0.7) & (g < 0.35) & (b < 0.35)
    green = (g > 0.35) & (g - r > 0.15) & (g - b > 0.1)
    counts = {
        name: int(mask.sum())
        for name, mask in (("blue", blue), ("orange", orange), ("red", red), ("green", green))
    }
    assert counts["blue"] > 1000 and counts["orange"] > 500, counts
    assert counts["red"] > 100 and counts["green"] > 50, counts
    for group in ("ghost", "trail"):
        js(page.driver, f"node(['meshcat', '{group}']).object.visible = false;")
        hidden = _frame(page.driver)
        js(page.driver, f"node(['meshcat', '{group}']).object.visible = true;")
        changed = int((np.abs(hidden - image).max(axis=2) > 0.1).sum())
        assert changed > 50, f"hiding the {group} changed only {changed} pixels"
