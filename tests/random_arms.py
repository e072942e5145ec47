"""Random serial arms written as URDF: what the tests of the robot-derived gains and the step
check draw (issue 50): 2–7 revolute joints about mixed axes, link masses and inertias spanning
four decades, centres of mass off the link axes, limits that leave every joint room."""

from __future__ import annotations

from pathlib import Path

import numpy as np

AXES = ("0 0 1", "0 1 0", "1 0 0")


def random_arm_urdf(rng: np.random.Generator, joints: int, name: str = "random_arm") -> str:
    """A serial arm of ``joints`` revolute joints; link masses 10^U(−2, 2) kg, their principal
    moments m (0.02 to 0.3 m)² × factors within the triangle inequality, rotated at random, the
    centre of mass offset by up to 0.1 m off the link's axis."""
    links = ['<link name="base"/>']
    body = []
    parent = "base"
    for j in range(joints):
        mass = 10.0 ** rng.uniform(-2.0, 2.0)
        size = rng.uniform(0.02, 0.3)
        moments = mass * size**2 * np.sort(rng.uniform(0.3, 1.0, 3))
        moments[2] = min(moments[2], 0.999 * (moments[0] + moments[1]))  # a body, not a plate
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        inertia = q @ np.diag(moments) @ q.T
        length = rng.uniform(0.05, 0.5)
        com = (rng.uniform(0.0, length), rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1))
        child = f"link{j + 1}"
        offset = "0 0 0.1" if j == 0 else f"{rng.uniform(0.05, 0.5):.6g} 0 0"
        body.append(
            f'<joint name="joint{j + 1}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{offset}"/><axis xyz="{AXES[int(rng.integers(3))]}"/>'
            '<limit lower="-2.5" upper="2.5" effort="0" velocity="0"/></joint>'
        )
        i = inertia
        links.append(
            f'<link name="{child}"><inertial><origin xyz="{com[0]:.6g} {com[1]:.6g} {com[2]:.6g}"/>'
            f'<mass value="{mass:.9g}"/><inertia ixx="{i[0, 0]:.12g}" ixy="{i[0, 1]:.12g}" ixz="{i[0, 2]:.12g}" '
            f'iyy="{i[1, 1]:.12g}" iyz="{i[1, 2]:.12g}" izz="{i[2, 2]:.12g}"/></inertial></link>'
        )
        parent = child
    body.append(
        f'<joint name="tool" type="fixed"><parent link="{parent}"/><child link="tool"/>'
        '<origin xyz="0.1 0 0"/></joint>'
    )
    links.append('<link name="tool"/>')
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(links + body) + "\n</robot>\n"


def write_random_arm(folder: Path, seed: int, joints: int) -> Path:
    """:func:`random_arm_urdf` of ``seed`` written to ``folder`` (its path)."""
    path = folder / f"arm_{seed}_{joints}.urdf"
    path.write_text(random_arm_urdf(np.random.default_rng(seed), joints, f"arm_{seed}_{joints}"))
    return path
