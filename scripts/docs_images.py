"""Regenerate the images the README and docs/ show, from the current code.

    .venv/bin/python scripts/docs_images.py [NAME ...]     # default: all of them

Each image is made by running the toolkit (a report, a simulation, an exported animation)
and, for pages, photographing them in headless Chromium (Debian's ``chromium`` and
``chromium-driver``, as the browser tests use: ``scripts/install_browser.sh``). Images land
in ``docs/images/``; ``tests/test_docs_images.py`` checks that every image a page links
decodes and is not blank. Numbers the docs quote beside the images are printed.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
sys.path.insert(0, str(ROOT / "tests"))  # the one Chromium starter, shared with the browser tests

from browser import start_chromium  # noqa: E402

from twolink_pin import SimulationConfig, load_robot, make_scenario, read_trajectory_file, simulate  # noqa: E402
from twolink_pin.plotting import save_end_effector_figure  # noqa: E402


def _photograph(url: str, out: Path, width: int, height: int, ready: str | None = None) -> Path:
    """A PNG of ``url`` in a ``width`` × ``height`` window, once ``ready`` (JavaScript) holds."""
    with start_chromium(width, height) as driver:
        driver.execute_cdp_cmd(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
        )
        driver.get(url)
        deadline = time.monotonic() + 60
        while ready and not driver.execute_script(ready):
            if time.monotonic() > deadline:
                raise RuntimeError(f"{url} never became ready ({ready})")
            time.sleep(0.2)
        time.sleep(1.0)  # a few frames of the animation
        out.parent.mkdir(parents=True, exist_ok=True)
        driver.save_screenshot(str(out))
    return out


SCENE_READY = "return window.sceneLoaded === true;"


def report() -> list[Path]:
    """The twolink's HTML report (``make demo``'s page), top of the page."""
    from twolink_pin.report import ReportOptions, build_report

    with tempfile.TemporaryDirectory() as tmp:
        build_report(Path(tmp) / "out", ReportOptions(animation=False))
        return [_photograph((Path(tmp) / "out" / "index.html").as_uri(), IMAGES / "report.png", 1100, 900)]


def animation() -> list[Path]:
    """The twolink's exported meshcat animation (adaptive law), mid-run."""
    from twolink_pin.trajectory import default_trajectory
    from twolink_pin.visualization import write_html

    robot = load_robot("twolink")
    controller, plant = make_scenario("adaptive", robot)
    trajectory = default_trajectory(robot)
    result = simulate(controller, plant, trajectory, SimulationConfig(duration=8.0))
    with tempfile.TemporaryDirectory() as tmp:
        path = write_html(robot, result.t, result.q, result.q_des, path=Path(tmp) / "a.html")
        return [_photograph(path.as_uri(), IMAGES / "animation.png", 800, 500, SCENE_READY)]


def ur5_square() -> list[Path]:
    """docs/any_robot.md: the UR5 on examples/ur5_square.toml with the adaptive law from
    p̂(0) = 0.5 β, 32 s: the end-effector figure and the meshcat view with its meshes."""
    from twolink_pin.kinematics import joint_positions
    from twolink_pin.metrics import compute_metrics
    from twolink_pin.visualization import write_html

    robot = load_robot("ur5")
    trajectory = read_trajectory_file(ROOT / "examples" / "ur5_square.toml", robot)
    controller, plant = make_scenario("adaptive", robot)
    result = simulate(controller, plant, trajectory, SimulationConfig(duration=32.0))
    metrics = compute_metrics(result)
    figure = save_end_effector_figure(
        robot, result, IMAGES / "ur5_square_end_effector.png", title="UR5, adaptive law from p̂(0) = 0.5 β"
    )
    actual = joint_positions(robot, result.q)[:, -1, :]
    desired = joint_positions(robot, result.q_des)[:, -1, :]
    last = result.t >= result.t[-1] - result.reference_period
    corners_y, corners_z = (-0.1, 0.1), (0.2, 0.4)
    off_square = np.minimum.reduce(
        [np.abs(desired[:, 1] - c) for c in corners_y] + [np.abs(desired[:, 2] - c) for c in corners_z]
    )
    print(
        f"ur5_square: final-period max |e| per joint [rad] {np.round(metrics.final_period_max_abs_e, 5).tolist()}"
    )
    print(
        f"ur5_square: final-period max |x - x_d| {np.linalg.norm(actual - desired, axis=1)[last].max() * 1e3:.3f} mm"
    )
    print(
        f"ur5_square: desired path's largest distance from the square's edges {off_square.max() * 1e3:.2f} mm"
    )
    print(
        f"ur5_square: peak |tau| / limit {np.round(np.abs(result.tau).max(axis=0) / result.torque_limits, 3).tolist()}"
    )
    error = np.abs(result.p_hat[-1] - result.p_true)
    print(f"ur5_square: |p_hat - beta| at 32 s: max {error.max():.3g}, median {np.median(error):.3g}")
    via = joint_positions(robot, trajectory.via_q)[:, -1, :]
    with tempfile.TemporaryDirectory() as tmp:
        path = write_html(robot, result.t, result.q, result.q_des, path=Path(tmp) / "u.html", via_points=via)
        shot = _photograph(path.as_uri(), IMAGES / "ur5_square_meshcat.png", 900, 600, SCENE_READY)
    return [figure, shot]


MAKERS: dict[str, Callable[[], list[Path]]] = {
    "report": report,
    "animation": animation,
    "ur5_square": ur5_square,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", choices=[*MAKERS, []], help="images to make (default: all)")
    names = parser.parse_args().names or list(MAKERS)
    for name in names:
        for path in MAKERS[name]():
            print(f"wrote {path.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
