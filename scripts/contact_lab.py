"""The contact lab of docs/contact.md: hybrid, force and impedance side by side against a surface.

    .venv/bin/python scripts/contact_lab.py                       # both arms, figures into docs/images
    .venv/bin/python scripts/contact_lab.py --robots twolink --duration 3 --out /tmp/lab

On the twolink the end effector approaches the wall of ``examples/wall.toml`` (1000 N/m, μ =
0.2), presses 10 N, slides 0.2 m along it and back, and leaves (``examples/wall_slide.toml``);
on the Panda the hand does the same on the table of ``examples/table.toml``
(``examples/panda_table_slide.toml``). Each law runs on the Pinocchio plant and on the MuJoCo
plant (``--plants``; MuJoCo's own contact, :mod:`twolink_pin.mujoco_contact`) with its defaults
but impedance's stiffness (1000 N/m: with the surface in series, the reference's depth gives
about 10 N). Prints one Markdown table per arm (force RMS and max error from 0.5 s after the
first contact, peak impact force, RMS position error along the surface, max penetration: the
contact metrics, :mod:`twolink_pin.contact_metrics`; a row per law and plant) and writes
``contact_twolink.png`` and ``contact_panda.png`` (``contact_twolink_mujoco.png`` and
``contact_panda_mujoco.png`` on MuJoCo: the force with the desired force, the position along
the surface, the penetration: :func:`~twolink_pin.plotting.contact.save_contact_figure`). The same runs are
``twolink-pin compare hybrid force impedance --scene … --trajectory …`` (the page's commands).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
LABS: dict[str, dict[str, Any]] = {
    "twolink": {
        "scene": "wall.toml",
        "trajectory": "wall_slide.toml",
        "impedance": {"k": 1000.0, "d": 300.0},
        "figure": "contact_twolink.png",
    },
    "panda": {
        "scene": "table.toml",
        "trajectory": "panda_table_slide.toml",
        "impedance": {"k": 1000.0, "d": 100.0},
        "figure": "contact_panda.png",
    },
}
LAWS = ("hybrid", "force", "impedance")
COLUMNS = {
    "force_rms_error": "force RMS error [N]",
    "force_max_error": "force max error [N]",
    "peak_impact_force": "peak impact [N]",
    "tangent_rms_mm": "position error along the surface, RMS [mm]",
    "max_penetration_mm": "max penetration [mm]",
}


PLANTS = {"pinocchio": "", "mujoco": "_mujoco"}
"""The plants each law runs on (``PlantOptions.engine``) and their figures' suffix."""


def lab(robot_name: str, duration: float, out: Path, plants: list[str]) -> str:
    """Run the lab on ``robot_name`` for ``duration`` [s] on each plant of ``plants``; its table
    (Markdown: a row per law and plant), a figure per plant in ``out``."""
    from twolink_pin import load_robot
    from twolink_pin.contact import read_scene
    from twolink_pin.contact_metrics import contact_metrics
    from twolink_pin.plant_options import PlantOptions
    from twolink_pin.plotting.contact import save_contact_figure
    from twolink_pin.run_spec import RunSpec
    from twolink_pin.simulation import SimulationConfig, simulate
    from twolink_pin.trajectory import read_trajectory_file

    setup = LABS[robot_name]
    robot = load_robot(robot_name)
    scene = read_scene(EXAMPLES / setup["scene"])
    trajectory = read_trajectory_file(EXAMPLES / setup["trajectory"], robot)
    config = SimulationConfig(duration=duration, q0_offset=0.0)
    rows = []
    for engine in plants:
        results = {}
        for law in LAWS:
            gains = setup["impedance"] if law == "impedance" else {}
            plant = PlantOptions(scene=scene, engine=engine)
            spec = RunSpec(law=law, gains=tuple(gains.items()), plant=plant, simulation=config)
            start = time.perf_counter()
            result = simulate(*spec.build(robot), trajectory, config)
            metrics = contact_metrics(result, robot)
            assert metrics is not None
            results[law] = result
            values = metrics._asdict()
            rows.append(f"| {law} | {engine} | " + " | ".join(f"{values[k]:.3g}" for k in COLUMNS) + " |")
            print(f"{robot_name} {law} {engine}: {time.perf_counter() - start:.1f} s", file=sys.stderr)
        name = setup["figure"].replace(".png", f"{PLANTS[engine]}.png")
        title = f"the contact lab on {robot_name}, {engine} plant"
        figure = save_contact_figure(results, robot, out / name, title)
        print(f"wrote {figure}", file=sys.stderr)
    head = f"| {robot_name} | plant | " + " | ".join(COLUMNS.values()) + " |"
    return "\n".join([head, "|---|---|" + "---:|" * len(COLUMNS), *rows])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", choices=sorted(LABS), default=list(LABS))
    parser.add_argument("--plants", nargs="+", choices=sorted(PLANTS), default=list(PLANTS))
    parser.add_argument("--duration", type=float, default=6.0, help="simulated time [s] (default 6)")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images", help="folder of the figures")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for robot_name in args.robots:
        print(lab(robot_name, args.duration, args.out, args.plants), end="\n\n")


if __name__ == "__main__":
    main()
