"""Regenerate the images the README and docs/ show, from the current code.

    .venv/bin/python scripts/docs_images.py [NAME ...] [--out DIR]   # default: all, into docs/images

Each image is made by running the toolkit (a report, a simulation, an exported or live
animation, the package's figures) and, for pages, photographing them in headless Chromium
(Debian's ``chromium`` and ``chromium-driver``, as the browser tests use:
``scripts/install_browser.sh``). Images land in ``docs/images/``;
``tests/test_docs_images.py`` checks that every image a page links exists, decodes, has a
sensible size and is not blank, and that every image here is linked. Numbers the docs
quote beside the images are printed. The tutorial's figures are not made here: the site
shows the ones the executed notebook draws (``docs/hooks/tutorial_page.py``).

=============  ==============================================================  =========
name           image(s)                                                         about
=============  ==============================================================  =========
report         report.png: the HTML report (``make demo``), top of the page     20 s
animation      animation.png: the exported meshcat animation (adaptive, 8 s)    5 s
live           live.png: the same run served live (``twolink-pin animate``)     10 s
figures        trajectory_workspace.png, adaptive_theta1.png                    10 s
ur5_square     ur5_square_end_effector.png, ur5_square_meshcat.png              40 s
tune           tune.png: ``twolink-pin tune pd`` in the browser, after one run  30 s
limits         limits_panda_fold.png, limits_qp_osc_task_error.png:             20 s
               docs/control_within_limits.md's demo (osc and qp-osc)
within_limits  within_limits_*.png: the retimed and the least-effort twolink    5 s
mpc            limits_mpc_twolink.png: docs/control_within_limits.md's demo (a)   5 s
               (mpc and computed-torque --saturate on the retimed twolink)
=============  ==============================================================  =========
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
IMAGES = ROOT / "docs" / "images"
"""Where the images go (``--out`` changes it)."""
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
LIVE_READY = (  # the live server sends the scene tree in its own order: wait for the last pieces
    "var n = viewer.scene_tree, path = ['meshcat', 'via', '4', '<object>'];"
    "for (var i = 0; i < path.length && n; i++) { n = n.children[path[i]]; }"
    "return !!(n && n.object && n.object.type === 'Mesh' && viewer.animator.actions.length > 0);"
)
SEEK = "viewer.animator.play(); viewer.animator.pause(); viewer.animator.seek({t}); viewer.set_dirty(); return true;"


def _adaptive_run(duration: float = 8.0) -> tuple[Any, Any, Any]:
    """The twolink, its reference and an adaptive-law run of ``duration`` [s]."""
    from twolink_pin.trajectory import default_trajectory

    robot = load_robot("twolink")
    controller, plant = make_scenario("adaptive", robot)
    trajectory = default_trajectory(robot)
    return robot, trajectory, simulate(controller, plant, trajectory, SimulationConfig(duration=duration))


def report() -> list[Path]:
    """The twolink's HTML report (``make demo``'s page), top of the page."""
    from twolink_pin.report import ReportOptions, build_report

    with tempfile.TemporaryDirectory() as tmp:
        build_report(Path(tmp) / "out", ReportOptions(animation=False))
        return [_photograph((Path(tmp) / "out" / "index.html").as_uri(), IMAGES / "report.png", 1100, 900)]


def animation() -> list[Path]:
    """The twolink's exported meshcat animation (adaptive law), mid-run."""
    from twolink_pin.visualization import write_html

    robot, _, result = _adaptive_run()
    with tempfile.TemporaryDirectory() as tmp:
        path = write_html(robot, result.t, result.q, result.q_des, path=Path(tmp) / "a.html")
        return [_photograph(path.as_uri(), IMAGES / "animation.png", 800, 500, SCENE_READY)]


def live() -> list[Path]:
    """The same run served live by meshcat on 127.0.0.1 (``twolink-pin animate adaptive``),
    with the report's via points, paused at 1.5 s."""
    from twolink_pin.twolink.reference import REPORT_VIA_XY
    from twolink_pin.visualization import serve

    robot, _, result = _adaptive_run()
    with serve(robot, result.t, result.q, result.q_des, via_points=REPORT_VIA_XY, quiet=True) as viewer:
        ready = f"if (!(function () {{ {LIVE_READY} }})()) return false; {SEEK.format(t=1.5)}"
        return [_photograph(viewer.url, IMAGES / "live.png", 800, 500, ready)]


def figures() -> list[Path]:
    """The package's own figures: the reference's workspace view (docs/trajectory.md) and
    joint 1 of a 30-s adaptive run (docs/controllers.md)."""
    import shutil

    from twolink_pin.feasibility import check_torques
    from twolink_pin.plotting import save_simulation_figures, save_trajectory_figures

    robot, trajectory, result = _adaptive_run(30.0)
    with tempfile.TemporaryDirectory() as tmp:
        made = save_trajectory_figures(robot, trajectory, check_torques(robot, trajectory), tmp)
        made += save_simulation_figures(
            result, tmp, prefix="adaptive", title="Slotine–Li adaptive, p̂(0) = 0.5 p"
        )
        wanted = {
            "trajectory_workspace.png": "trajectory_workspace.png",
            "adaptive_theta1.png": "adaptive_theta1.png",
        }
        out = []
        for path in made:
            if path.name in wanted:
                target = IMAGES / wanted[path.name]
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(path, target)
                out.append(target)
        missing = set(wanted) - {p.name for p in made}
        if missing:
            raise RuntimeError(
                f"the plotting module no longer writes {sorted(missing)}: update scripts/docs_images.py"
            )
    return out


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


TUNE_READY = (  # the first run shown, the scene faded in, the WebGL notice closed
    "document.querySelectorAll('.mantine-Notification-root').forEach(function (e) { e.remove(); });"
    "return performance.now() > 8000 && document.body.innerText.includes('run 1:')"  # the scene has faded in
    " && document.body.innerText.includes('this run');"
)


def tune() -> list[Path]:
    """``twolink-pin tune pd`` as a user starts it, photographed after its first run."""
    import json
    import signal
    import subprocess

    command = [sys.executable, "-m", "twolink_pin_entry", "tune", "pd", "--json", "--no-browser"]
    proc = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        url = json.loads(proc.stdout.readline())["url"]
        proc.stdout.readline()  # the first run
        return [_photograph(url, IMAGES / "tune.png", 1366, 768, TUNE_READY)]  # a laptop's screen
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=60)


LIMITS_DEMO = (
    "compare osc qp-osc --robot panda --payload 3 --trajectory examples/panda_fold_pose.toml "
    "--q0-offset 1.5 0 0 0 0 0 0 --duration 2.5"
)
"""docs/control_within_limits.md's compare command (its runs, without ``--out``)."""


def limits() -> list[Path]:
    """docs/control_within_limits.md: the page's two runs (osc and qp-osc on the Panda carrying
    3 kg, starting 1.5 rad round from the folded-elbow path) against joint 4's range and joint 6's
    effort limit, and qp-osc's task error; prints the numbers the page quotes."""
    import shutil

    from twolink_pin.limits import POSITION, joint_limits
    from twolink_pin.plotting import save_limits_figure, save_task_error_figure

    robot = load_robot("panda", payload=3.0)
    trajectory = read_trajectory_file(ROOT / "examples" / "panda_fold_pose.toml", robot)
    config = SimulationConfig(duration=2.5, q0_offset=(1.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    runs = {}
    for law in ("osc", "qp-osc"):
        controller, plant = make_scenario(law, robot)
        runs[law] = simulate(controller, plant, trajectory, config)
    bounds = joint_limits(robot)
    for law, run in runs.items():
        past = bounds.excess(POSITION, run.q).max(axis=0)
        share = np.abs(run.tau_command).max(axis=0) / bounds.effort
        speed = np.abs(run.v).max(axis=0) / bounds.velocity
        print(
            f"limits: {law}: joint 4 from {run.q[:, 3].min():.4g} to {run.q[:, 3].max():.4g} rad (past its range by "
            f"{past[3]:.3g} rad; every joint: largest {past.max():.3g}), peak |tau| / limit {np.round(share, 3).tolist()}, "
            f"peak |v| / limit {np.round(speed, 3).tolist()}"
        )
    out = [
        save_limits_figure(
            runs,
            bounds,
            IMAGES / "limits_panda_fold.png",
            position_joint=3,
            torque_joint=5,
            title="Panda with 3 kg, starting 1.5 rad round from the folded-elbow path",
        )
    ]
    with tempfile.TemporaryDirectory() as tmp:
        made = save_task_error_figure(robot, runs["qp-osc"], Path(tmp) / "task.png", title="qp-osc")
        target = IMAGES / "limits_qp_osc_task_error.png"
        shutil.copyfile(made, target)
        out.append(target)


def within_limits() -> list[Path]:
    """docs/within_limits.md's figures: the report's path retimed (TOPP-RA), its torque and
    velocity against the limits; the minimum-effort twolink's torque beside the polynomial's."""
    import shutil

    from twolink_pin.limits import reference_motion
    from twolink_pin.plotting.within_limits import save_limit_figures
    from twolink_pin.trajectory import default_trajectory, optimize, time_optimal
    from twolink_pin.trajectory.retiming import verify_motion

    robot = load_robot("twolink")
    reference = default_trajectory(robot)
    polynomial = reference_motion(robot, reference, 2001)
    retimed = time_optimal(robot, reference)
    least = optimize(robot, reference, "effort")
    print(
        f"retimed: {retimed.duration:.4f} s; least effort {least.effort:.4g} against {least.reference_effort:.4g}"
    )
    wanted = {
        "time_optimal_torque.png": "within_limits_time_optimal_torque.png",
        "time_optimal_velocity.png": "within_limits_time_optimal_velocity.png",
        "least_effort_torque.png": "within_limits_least_effort_torque.png",
    }
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        made = save_limit_figures(
            verify_motion(robot, retimed.trajectory, 4), retimed.limits, tmp, "time_optimal_",
            "twolink, the report's path retimed (TOPP-RA)", retimed.active, polynomial,
        )  # fmt: skip
        made += save_limit_figures(
            verify_motion(robot, least.trajectory, 20), least.limits, tmp, "least_effort_",
            "twolink, least ∫τᵀτ dt near the path (the default)", (), polynomial,
        )  # fmt: skip
        for path in made:
            if path.name in wanted:
                target = IMAGES / wanted[path.name]
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(path, target)
                out.append(target)
    return out


MPC_DEMO = "--trajectory {tmp}/twolink_time_optimal.toml --model examples/twolink_light.urdf --duration 2.112"
"""docs/control_within_limits.md's demo (a): the retimed twolink, the law's model 20 % light."""


def mpc() -> list[Path]:
    """docs/control_within_limits.md, demo (a): mpc and computed-torque --saturate on the
    twolink's time-optimal retiming, both believing links 20 % light; joint 2's velocity and
    torque against its limits, from the runs the page's commands save; prints their numbers."""
    import shlex

    from twolink_pin.cli import main as cli
    from twolink_pin.limits import EFFORT, VELOCITY, joint_limits
    from twolink_pin.plotting import save_velocity_limits_figure
    from twolink_pin.simulation.storage import load_result

    bounds = joint_limits(load_robot("twolink"))
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        cli(["trajectory", "--time-optimal", "--save", f"{tmp}/twolink_time_optimal.toml"])
        for label, law in (("mpc", "mpc"), ("computed-torque --saturate", "computed-torque --saturate")):
            argv = [
                *shlex.split(law),
                *shlex.split(MPC_DEMO.format(tmp=tmp)),
                "--save",
                f"{tmp}/{law.split()[0]}.npz",
            ]
            cli(["simulate", *argv])
            runs[label] = load_result(f"{tmp}/{law.split()[0]}.npz")
    for label, run in runs.items():
        rms = np.sqrt(np.mean(run.e**2, axis=0))
        print(
            f"mpc: {label}: RMS e {np.round(rms, 4).tolist()} rad, peak |v| / limit "
            f"{np.round(np.abs(run.v).max(axis=0) / bounds.velocity, 3).tolist()}, largest torque excess "
            f"{bounds.excess(EFFORT, run.tau_command).max():.3g} N·m, velocity excess {bounds.excess(VELOCITY, run.v).max():.3g} rad/s"
        )
    return [
        save_velocity_limits_figure(
            runs,
            bounds,
            IMAGES / "limits_mpc_twolink.png",
            joint=1,
            title="twolink on its time-optimal retiming, the laws' links 20 % light",
        )
    ]


def mujoco() -> list[Path]:
    """docs/mujoco.md's figures: the report's sim-to-sim section for the course's five laws (each
    effect's difference from the Pinocchio plant, 2 periods), and computed torque on Pinocchio's
    plant and on MuJoCo with each of the twolink's effects overlaid (12 s); prints the table."""
    from twolink_pin.law_variant import parse_variant
    from twolink_pin.plotting.sim_to_sim import save_sim_to_sim_figure
    from twolink_pin.report import ReportOptions
    from twolink_pin.report.sim_to_sim import sim_to_sim_law

    options = ReportOptions(workers=1)
    laws = [
        sim_to_sim_law(law, parse_variant(law), options)
        for law in ("pd", "computed-torque", "robust", "adaptive", "adaptive-friction")
    ]
    for law in laws:
        for row in law["rows"]:
            print(
                f"mujoco: {law['law']:18s} {row['short']:18s} RMS {row['rms_e']:.5g} max {row['max_e']:.5g} "
                f"Δ {row.get('delta_rms_e', 0):+.3e} {row.get('delta_max_e', 0):+.3e}"
            )
    out = [
        save_sim_to_sim_figure(
            laws, IMAGES / "mujoco_sim_to_sim.png", "twolink: what each effect on MuJoCo changes"
        )
    ]
    return [*out, *mujoco_overlay()]


def mujoco_overlay() -> list[Path]:
    """docs/mujoco.md's second figure: computed torque on Pinocchio's plant and on MuJoCo with the
    twolink's armature alone and with every effect, overlaid over 12 s (three runs: the legend's
    one row)."""
    from twolink_pin import PlantOptions, RunSpec, SimulationConfig, default_trajectory, simulate
    from twolink_pin.plotting.overlay import save_overlay_figure

    robot = load_robot("twolink")
    reference = default_trajectory(robot)
    runs = {}
    for label, plant in (
        ("Pinocchio", PlantOptions()),
        ("MuJoCo + armature", PlantOptions(engine="mujoco", armature="arm")),
        (
            "MuJoCo, every effect",
            PlantOptions(
                engine="mujoco",
                armature="arm",
                joint_damping="arm",
                frictionloss="arm",
                saturate=True,
                integrator="implicitfast",
            ),
        ),
    ):
        spec = RunSpec(law="computed-torque", plant=plant, simulation=SimulationConfig(duration=12.0))
        runs[label] = simulate(*spec.build(robot), reference, spec.simulation)
    return [
        save_overlay_figure(
            runs,
            IMAGES / "mujoco_computed_torque.png",
            "computed-torque on the twolink: Pinocchio, and MuJoCo with the arm's effects",
        )
    ]


MAKERS: dict[str, Callable[[], list[Path]]] = {
    "report": report,
    "animation": animation,
    "live": live,
    "figures": figures,
    "ur5_square": ur5_square,
    "tune": tune,
    "limits": limits,
    "within_limits": within_limits,
    "mpc": mpc,
    "mujoco": mujoco,
    "mujoco_overlay": mujoco_overlay,
}


def main(argv: list[str] | None = None) -> None:
    global IMAGES
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", choices=[*MAKERS, []], help="images to make (default: all)")
    parser.add_argument(
        "--out", type=Path, default=IMAGES, help="folder to write into (default: docs/images)"
    )
    args = parser.parse_args(argv)
    IMAGES = args.out.resolve()
    for name in args.names or list(MAKERS):
        for path in MAKERS[name]():
            shown = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
            print(f"wrote {shown}")


if __name__ == "__main__":
    main()
