"""URDFs as the field writes them (issue 50 §3): a static base of mass 0, a thin rod's zero
principal moment, and inertias that break the triangle inequality — refused naming the link and
``--repair-inertias``, which writes in the nearest consistent inertia and lists each change."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from twolink_pin import load_robot
from twolink_pin.cli import main
from twolink_pin.errors import InvalidURDFError
from twolink_pin.model.inertia_repair import inertia_matrix, nearest_consistent
from twolink_pin.model.urdf_validation import TRIANGLE_RTOL

LINK2 = '<inertia ixx="{a}" ixy="{d}" ixz="0" iyy="{b}" iyz="0" izz="{c}"/>'


def _arm(base: str = "", inertia: str = LINK2.format(a=0.05, b=0.05, c=0.08, d=0.0)) -> str:
    """A 2-joint arm on a world link fixed to a base (``base``: the base link's inertial)."""
    return f"""<?xml version="1.0"?>
<robot name="quirks">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base_link"/></joint>
  <link name="base_link">{base}</link>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="l1"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
  <link name="l1"><inertial><origin xyz="0.2 0 0"/><mass value="3"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.05"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="20" velocity="3"/></joint>
  <link name="l2"><inertial><origin xyz="0.15 0.01 0"/><mass value="1.5"/>{inertia}</inertial></link>
</robot>
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "quirks.urdf"
    path.write_text(text)
    return path


def test_a_static_base_of_mass_zero_with_an_inertia_is_accepted(tmp_path: Path) -> None:
    base = (
        '<inertial><mass value="0.0"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
    )
    robot = load_robot(_write(tmp_path, _arm(base)))
    assert robot.nv == 2
    assert any("base_link" in note and "never moves" in note for note in robot.notes)


def test_a_moving_link_of_mass_zero_with_an_inertia_is_still_refused(tmp_path: Path) -> None:
    text = _arm().replace('<mass value="1.5"/>', '<mass value="0.0"/>')
    with pytest.raises(InvalidURDFError, match=r"link 'l2' .*mass value=\"0.0\" must be a finite number > 0"):
        load_robot(_write(tmp_path, text))


def test_a_thin_rods_zero_moment_is_accepted_with_a_note_where_m_is_positive_definite(tmp_path: Path) -> None:
    rod = LINK2.format(a=0.0, b=0.01, c=0.01, d=0.0)  # a rod along x, the joint about y: M > 0
    robot = load_robot(_write(tmp_path, _arm(inertia=rod)))
    assert any("l2" in note and "principal moment is 0" in note for note in robot.notes)
    M = pin.crba(robot.model, robot.model.createData(), robot.home)
    assert np.linalg.eigvalsh(np.triu(M) + np.triu(M, 1).T).min() > 0


BROKEN = LINK2.format(a=0.01, b=0.01, c=0.0203, d=0.0)
"""A CAD export's inertia: izz 1.5 % beyond ixx + iyy."""


def test_a_triangle_violation_is_refused_naming_the_link_and_the_option(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf = _write(tmp_path, _arm(inertia=BROKEN))
    assert main(["info", "--robot", str(urdf)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "link 'l2'" in err[0] and "triangle inequality" in err[0]
    assert "--repair-inertias" in err[0]


@pytest.mark.parametrize(
    "values", [(0.01, 0.0, 0.0, 0.01, 0.0, 0.0203), (0.02, 0.004, -0.001, 0.003, 0.0, 0.03)]
)
def test_the_repair_is_the_nearest_consistent_inertia(values: tuple[float, ...]) -> None:
    """Its moments meet the triangle inequality (the largest = the sum of the others), it keeps
    the principal axes, the listed change is ‖I' − I‖_F = δ/√3, and no other consistent matrix
    among 2000 random ones is nearer."""
    change = nearest_consistent("l2", values)
    before, after = inertia_matrix(change.before), inertia_matrix(change.after)
    moments = np.linalg.eigvalsh(after)
    assert moments[2] <= (moments[0] + moments[1]) * (1 + TRIANGLE_RTOL)
    assert moments[2] == pytest.approx(moments[0] + moments[1], rel=1e-12)  # on the boundary
    np.testing.assert_allclose(before @ after, after @ before, atol=1e-15)  # same eigenvectors
    assert change.change == pytest.approx(np.linalg.norm(after - before), rel=1e-12)
    lam = np.linalg.eigvalsh(before)
    assert change.change == pytest.approx((lam[2] - lam[0] - lam[1]) / np.sqrt(3), rel=1e-9)
    assert change.relative == pytest.approx(change.change / np.linalg.norm(before), rel=1e-12)
    rng = np.random.default_rng(0)
    for _ in range(2000):  # random consistent inertias near the original
        other = before + rng.normal(scale=np.linalg.norm(before) * 0.3, size=(3, 3))
        other = 0.5 * (other + other.T)
        m = np.linalg.eigvalsh(other)
        if m[0] >= 0 and m[2] <= m[0] + m[1]:
            assert np.linalg.norm(other - before) >= change.change * (1 - 1e-12)


def test_repair_inertias_runs_every_command_and_lists_each_change(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf = _write(tmp_path, _arm(inertia=BROKEN))
    assert main(["info", "--robot", str(urdf), "--repair-inertias", "--json"]) == 0
    captured = capsys.readouterr()
    repaired = json.loads(captured.out)["repaired_inertias"]
    assert [r["link"] for r in repaired] == ["l2"]
    assert "twolink-pin: note: repaired inertia of link 'l2'" in captured.err and "kg·m²" in captured.err
    expected = nearest_consistent("l2", (0.01, 0.0, 0.0, 0.01, 0.0, 0.0203))
    assert repaired[0]["change"] == pytest.approx(expected.change, rel=1e-12)
    robot = load_robot(urdf, repair_inertias=True)  # the model holds the repaired inertia
    body = robot.model.inertias[2].inertia
    np.testing.assert_allclose(np.linalg.eigvalsh(body), expected.moments_after, rtol=1e-9)
    argv = ["simulate", "pd", "--robot", str(urdf), "--repair-inertias", "--duration", "0.05"]
    assert main(argv) == 0
