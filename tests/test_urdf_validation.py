"""Tests of twolink_pin.urdf_validation.

Each bad description must raise InvalidURDFError naming the offending element and what was
expected. A few tests also show that Pinocchio 4.1 itself accepts the bad input (the reason
the validator exists); those never build the huge chain, which would segfault.
"""

from __future__ import annotations

import math
import re
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.errors import InvalidURDFError, TwolinkPinError
from twolink_pin.model.urdf_validation import MAX_LINKS, validate_urdf_file, validate_urdf_string

SHIPPED_URDF = Path(__file__).resolve().parents[1] / "robots" / "twolink.urdf"

GOOD_INERTIA = 'ixx="0.3" ixy="0" ixz="0" iyy="0.3" iyz="0" izz="0.3"'
GOOD_LIMIT = '<limit lower="-3" upper="3" effort="40" velocity="10"/>'


def arm(
    *,
    mass: str = '<mass value="2.0"/>',
    inertia: str = f"<inertia {GOOD_INERTIA}/>",
    inertial_origin: str = '<origin xyz="0.12 0 0" rpy="0 0 0"/>',
    joint2_type: str = "revolute",
    joint2_origin: str = '<origin xyz="0.38 0 0" rpy="0 0 0"/>',
    axis: str = '<axis xyz="0 0 1"/>',
    limit: str = GOOD_LIMIT,
    extra: str = "",
) -> str:
    """A valid 2-link arm; each argument replaces one piece of joint2 / link2 to break it."""
    return f"""<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link"/>
  <joint name="joint1" type="revolute">
    <parent link="base_link"/><child link="link1"/>
    <axis xyz="0 0 1"/>{GOOD_LIMIT}
  </joint>
  <link name="link1">
    <inertial><origin xyz="0.19 0 0"/><mass value="10"/><inertia {GOOD_INERTIA}/></inertial>
  </link>
  <joint name="joint2" type="{joint2_type}">
    <parent link="link1"/><child link="link2"/>
    {joint2_origin}{axis}{limit}
  </joint>
  <link name="link2">
    <inertial>{inertial_origin}{mass}{inertia}</inertial>
  </link>
  {extra}
</robot>
"""


def chain(n_links: int) -> str:
    """A valid serial chain of ``n_links`` links."""
    parts = ['<robot name="chain">', '<link name="link0"/>']
    for i in range(1, n_links):
        parts.append(
            f'<joint name="joint{i}" type="revolute"><parent link="link{i - 1}"/><child link="link{i}"/>'
            f'<origin xyz="0.01 0 0"/><axis xyz="0 0 1"/>{GOOD_LIMIT}</joint>'
            f'<link name="link{i}"><inertial><mass value="1"/><inertia {GOOD_INERTIA}/></inertial></link>'
        )
    parts.append("</robot>")
    return "\n".join(parts)


def rejected(xml: str) -> InvalidURDFError:
    """The error validate_urdf_string raises on ``xml``."""
    with pytest.raises(InvalidURDFError) as info:
        validate_urdf_string(xml)
    return info.value


def assert_rejected(xml: str, element: str, *reason_parts: str) -> InvalidURDFError:
    error = rejected(xml)
    assert error.element == element, str(error)
    for part in reason_parts:
        assert part in error.reason, str(error)
    assert str(error) == f"<string>: {element}: {error.reason}"
    return error


# --- valid descriptions ---------------------------------------------------------------------


def test_shipped_urdf_passes() -> None:
    validate_urdf_file(SHIPPED_URDF)
    validate_urdf_file(str(SHIPPED_URDF))
    validate_urdf_string(SHIPPED_URDF.read_text())


def test_helper_arm_is_valid_and_pinocchio_agrees(capfd: pytest.CaptureFixture[str]) -> None:
    xml = arm()
    validate_urdf_string(xml)
    model = pin.buildModelFromXML(xml)
    assert model.nq == 2
    assert model.inertias[2].mass == pytest.approx(2.0)
    assert capfd.readouterr().err == ""


def test_defaults_pass_absent_axis_absent_limit_and_massless_links() -> None:
    validate_urdf_string(arm(axis="", limit="", inertial_origin=""))
    validate_urdf_string('<robot name="one"><link name="only"/></robot>')
    validate_urdf_string(arm(axis="<axis/>"))  # no xyz: URDF default 1 0 0


def test_axis_and_limit_of_fixed_joint_are_ignored() -> None:
    validate_urdf_string(arm(joint2_type="fixed", axis='<axis xyz="0 0 0"/>', limit='<limit effort="-1"/>'))


# --- file and document ----------------------------------------------------------------------


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "absent.urdf"
    with pytest.raises(InvalidURDFError) as info:
        validate_urdf_file(path)
    assert info.value.path == str(path)
    assert info.value.element == "file"
    assert "file not found" in info.value.reason
    assert isinstance(info.value, TwolinkPinError)


def test_unreadable_file_is_reported_not_raised_as_oserror(tmp_path: Path) -> None:
    with pytest.raises(InvalidURDFError) as info:
        validate_urdf_file(tmp_path)  # a directory
    assert info.value.element == "file"
    assert "is a directory" in info.value.reason


def test_truncated_file_reports_parser_message_with_line_and_column(tmp_path: Path) -> None:
    text = SHIPPED_URDF.read_text()
    path = tmp_path / "truncated.urdf"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(InvalidURDFError) as info:
        validate_urdf_file(path)
    error = info.value
    assert error.path == str(path)
    assert error.element == "XML document"
    assert "not well-formed XML" in error.reason
    assert "line" in error.reason and "column" in error.reason
    assert "expected a complete, well-formed XML file" in error.reason


def test_empty_string() -> None:
    assert_rejected("", "XML document", "no element found: line 1, column 0")


def test_root_must_be_robot() -> None:
    assert_rejected('<model><link name="a"/></model>', "<model>", "root element is <model>; expected <robot>")


def test_robot_without_links() -> None:
    assert_rejected('<robot name="r"/>', "<robot>", "contains no <link>; expected at least one link")


# --- chain length ---------------------------------------------------------------------------


def test_6000_link_file_is_rejected_quickly_without_pinocchio(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Pinocchio 4.1 segfaults on this file: it must never be reached."""

    def forbidden(*args: object, **kwargs: object) -> None:
        raise AssertionError("Pinocchio must not be called on a 6000-link chain")

    for name in ("buildModelFromUrdf", "buildModelFromXML", "buildModelsFromUrdf"):
        monkeypatch.setattr(pin, name, forbidden)
    path = tmp_path / "long_chain.urdf"
    path.write_text(chain(6000))
    with pytest.raises(InvalidURDFError) as info:
        validate_urdf_file(path)
    assert info.value.element == "<robot>"
    assert "has 6000 links, more than the cap MAX_LINKS = 1000" in info.value.reason


def test_chain_at_the_cap_passes_and_pinocchio_builds_it(capfd: pytest.CaptureFixture[str]) -> None:
    """The cap is safe: Pinocchio parses a MAX_LINKS chain correctly."""
    xml = chain(MAX_LINKS)
    validate_urdf_string(xml)
    model = pin.buildModelFromXML(xml)
    assert model.nq == MAX_LINKS - 1
    assert capfd.readouterr().err == ""


def test_one_link_over_the_cap_is_rejected() -> None:
    assert_rejected(chain(MAX_LINKS + 1), "<robot>", f"has {MAX_LINKS + 1} links", f"MAX_LINKS = {MAX_LINKS}")


def test_too_many_joints_is_rejected() -> None:
    joints = "".join(
        f'<joint name="j{i}" type="fixed"><parent link="a"/><child link="b"/></joint>'
        for i in range(MAX_LINKS + 1)
    )
    xml = f'<robot name="r"><link name="a"/><link name="b"/>{joints}</robot>'
    assert_rejected(xml, "<robot>", f"has {MAX_LINKS + 1} joints, more than the cap MAX_LINKS = {MAX_LINKS}")


# --- names ----------------------------------------------------------------------------------


def test_link_without_name() -> None:
    xml = '<robot name="r"><link name="a"/><link/></robot>'
    assert_rejected(xml, "link #2", 'expected <link name="...">')


def test_duplicate_link_name() -> None:
    xml = arm(extra='<link name="link1"/>')
    assert_rejected(xml, "link 'link1'", "declared 2 times; expected unique link names")


def test_joint_without_name() -> None:
    xml = arm(extra='<link name="x"/><joint type="fixed"><parent link="link2"/><child link="x"/></joint>')
    assert_rejected(xml, "joint #3", 'expected <joint name="...">')


def test_duplicate_joint_name() -> None:
    xml = arm(
        extra='<link name="x"/>'
        '<joint name="joint1" type="fixed"><parent link="link2"/><child link="x"/></joint>'
    )
    assert_rejected(xml, "joint 'joint1'", "declared 2 times; expected unique joint names")


# --- inertial -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "value", ["-1.0", "0", "-0.0", "abc", "nan", "NaN", "inf", "1e400", "", "1_0", "1 2"]
)
def test_bad_mass_value(value: str) -> None:
    assert_rejected(
        arm(mass=f'<mass value="{value}"/>'),
        "link 'link2' <inertial><mass>",
        f'mass value="{value}" must be a finite number > 0 kg',
    )


@pytest.mark.parametrize("value", ["1", "2.5", ".5", "1.", "+3", "1e-3", "2E2", " 4 "])
def test_decimal_mass_spellings_pass(value: str) -> None:
    validate_urdf_string(arm(mass=f'<mass value="{value}"/>'))


def test_explicitly_massless_link_passes() -> None:
    """mass 0 with an all-zero inertia is a massless frame link (example-robot-data uses them)."""
    zero = '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
    validate_urdf_string(arm(mass='<mass value="0"/>', inertia=zero))


def test_missing_mass() -> None:
    assert_rejected(arm(mass=""), "link 'link2' <inertial><mass>", 'missing; expected <mass value="..."/>')
    assert_rejected(arm(mass="<mass/>"), "link 'link2' <inertial><mass>", "value is missing")


def test_missing_inertia() -> None:
    assert_rejected(arm(inertia=""), "link 'link2' <inertial><inertia>", "missing; expected <inertia")


def test_inertia_missing_attributes() -> None:
    assert_rejected(
        arm(inertia='<inertia ixx="1" iyy="1" izz="1"/>'),
        "link 'link2' <inertial><inertia>",
        "missing attribute(s) ixy, ixz, iyz; expected all six of ixx, ixy, ixz, iyy, iyz, izz",
    )


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "x", ""])
def test_inertia_attribute_not_finite(value: str) -> None:
    assert_rejected(
        arm(inertia=f'<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="{value}" izz="1"/>'),
        "link 'link2' <inertial><inertia>",
        f'iyz="{value}" must be a finite number (kg m^2)',
    )


@pytest.mark.parametrize(
    "attributes",
    [
        'ixx="-1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"',  # negative diagonal
        'ixx="1" ixy="2" ixz="0" iyy="1" iyz="0" izz="1"',  # positive diagonal, eigenvalue -1
    ],
)
def test_inertia_not_positive_semidefinite(attributes: str) -> None:
    assert_rejected(
        arm(inertia=f"<inertia {attributes}/>"),
        "link 'link2' <inertial><inertia>",
        "inertia matrix is not positive semidefinite: its eigenvalues are",
        "expected all >= 0",
    )


def test_inertia_violating_triangle_inequality() -> None:
    assert_rejected(
        arm(inertia='<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="3"/>'),
        "link 'link2' <inertial><inertia>",
        "principal moments (1, 1, 3) kg m^2 violate the triangle inequality: 3 > 1 + 1",
        "expected each moment <= the sum of the other two",
    )


def test_inertia_on_the_triangle_boundary_passes() -> None:
    """A thin plate: Izz = Ixx + Iyy exactly."""
    validate_urdf_string(arm(inertia='<inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/>'))


@pytest.mark.parametrize(
    ("origin", "message"),
    [
        ('<origin xyz="0 0"/>', 'xyz="0 0" must be 3 finite numbers (m)'),
        ('<origin xyz="0 0 nan"/>', 'xyz="0 0 nan" must be 3 finite numbers (m)'),
        ('<origin xyz="0 0 0 0"/>', 'xyz="0 0 0 0" must be 3 finite numbers (m)'),
        ('<origin rpy="a b c"/>', 'rpy="a b c" must be 3 finite numbers (rad)'),
    ],
)
def test_bad_inertial_origin(origin: str, message: str) -> None:
    assert_rejected(arm(inertial_origin=origin), "link 'link2' <inertial><origin>", message)


def test_two_inertials_in_one_link() -> None:
    xml = arm(
        extra=f'<link name="x"><inertial><mass value="1"/><inertia {GOOD_INERTIA}/></inertial>'
        f'<inertial><mass value="2"/><inertia {GOOD_INERTIA}/></inertial></link>'
        '<joint name="j3" type="fixed"><parent link="link2"/><child link="x"/></joint>'
    )
    assert_rejected(xml, "link 'x' <inertial>", "appears 2 times; expected at most one per link")


# --- joints ---------------------------------------------------------------------------------


def test_unknown_joint_type() -> None:
    assert_rejected(
        arm(joint2_type="hinge"),
        "joint 'joint2'",
        'type="hinge" is not a URDF joint type; expected one of continuous, fixed, floating, planar, '
        "prismatic, revolute",
    )


def test_missing_joint_type() -> None:
    xml = arm().replace('<joint name="joint2" type="revolute">', '<joint name="joint2">')
    assert_rejected(xml, "joint 'joint2'", "has no type; expected one of")


@pytest.mark.parametrize("joint_type", ["revolute", "continuous", "prismatic", "planar"])
@pytest.mark.parametrize("xyz", ["0 0 0", "0 0", "0 0 nan", "0 0 1e400", "z"])
def test_bad_axis(joint_type: str, xyz: str) -> None:
    assert_rejected(
        arm(joint2_type=joint_type, axis=f'<axis xyz="{xyz}"/>'),
        "joint 'joint2' <axis>",
        f'xyz="{xyz}" must be 3 finite numbers with a nonzero norm',
    )


def test_unnormalised_axis_passes() -> None:
    validate_urdf_string(arm(axis='<axis xyz="0 0 2"/>'))
    validate_urdf_string(arm(axis='<axis xyz="1e-9 0 0"/>'))


def test_bad_joint_origin() -> None:
    assert_rejected(
        arm(joint2_origin='<origin xyz="0.38 0 inf"/>'),
        "joint 'joint2' <origin>",
        'xyz="0.38 0 inf" must be 3 finite numbers (m)',
    )


@pytest.mark.parametrize(
    ("joint_type", "limit", "message"),
    [
        ("revolute", '<limit effort="-1" velocity="1"/>', 'effort="-1" must be a finite number >= 0 (N m)'),
        (
            "revolute",
            '<limit effort="1" velocity="nan"/>',
            'velocity="nan" must be a finite number >= 0 (rad/s)',
        ),
        (
            "continuous",
            '<limit effort="inf" velocity="1"/>',
            'effort="inf" must be a finite number >= 0 (N m)',
        ),
        ("prismatic", '<limit effort="-2" velocity="1"/>', 'effort="-2" must be a finite number >= 0 (N)'),
        (
            "prismatic",
            '<limit effort="1" velocity="-1"/>',
            'velocity="-1" must be a finite number >= 0 (m/s)',
        ),
        (
            "revolute",
            '<limit effort="1" velocity="1" lower="1" upper="-1"/>',
            'lower="1" > upper="-1"; expected lower <= upper (rad',
        ),
        (
            "revolute",
            '<limit effort="1" velocity="1" lower="0.5"/>',
            'lower="0.5" > upper="0"; expected lower <= upper',
        ),
        (
            "prismatic",
            '<limit effort="1" velocity="1" lower="0.2" upper="0.1"/>',
            'lower="0.2" > upper="0.1"; expected lower <= upper (m',
        ),
        (
            "revolute",
            '<limit effort="1" velocity="1" lower="abc" upper="1"/>',
            'lower="abc" must be a finite number (rad)',
        ),
        (
            "revolute",
            '<limit effort="1" velocity="1" lower="-1" upper="nan"/>',
            'upper="nan" must be a finite number (rad)',
        ),
    ],
)
def test_bad_limit(joint_type: str, limit: str, message: str) -> None:
    assert_rejected(arm(joint2_type=joint_type, limit=limit), "joint 'joint2' <limit>", message)


def test_continuous_joint_ignores_lower_upper() -> None:
    validate_urdf_string(
        arm(joint2_type="continuous", limit='<limit lower="1" upper="-1" effort="1" velocity="1"/>')
    )


def test_missing_parent() -> None:
    xml = arm().replace('<parent link="link1"/>', "")
    assert_rejected(xml, "joint 'joint2' <parent>", 'missing; expected <parent link="..."/>')


def test_parent_names_unknown_link() -> None:
    xml = arm().replace('<parent link="link1"/>', '<parent link="lnk1"/>')
    assert_rejected(
        xml,
        "joint 'joint2' <parent>",
        "link=\"lnk1\" names no declared link; expected one of 'base_link', 'link1', 'link2'",
    )


def test_child_names_unknown_link() -> None:
    xml = arm().replace('<child link="link2"/>', '<child link="link3"/>')
    assert_rejected(xml, "joint 'joint2' <child>", 'link="link3" names no declared link')


def test_joint_from_a_link_to_itself() -> None:
    xml = arm().replace('<child link="link2"/>', '<child link="link1"/>')
    assert_rejected(
        xml, "joint 'joint2' <child>", "link 'link1' is also the parent; expected two different links"
    )


def test_link_child_of_two_joints() -> None:
    xml = arm(
        extra='<joint name="joint3" type="fixed"><parent link="base_link"/><child link="link2"/></joint>'
    )
    assert_rejected(
        xml,
        "joint 'joint3' <child>",
        "link 'link2' is already the child of joint 'joint2'; "
        "expected each link to be the child of at most one joint",
    )


# --- tree -----------------------------------------------------------------------------------


def test_two_root_links() -> None:
    assert_rejected(
        arm(extra='<link name="floating_part"/>'),
        "<robot>",
        "has 2 root links ('base_link', 'floating_part'); expected exactly one link",
    )


def test_cycle_without_root() -> None:
    xml = """<robot name="r"><link name="a"/><link name="b"/>
      <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
      <joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint></robot>"""
    assert_rejected(xml, "<robot>", "has no root link", "the joints form a cycle")


def test_cycle_beside_the_root() -> None:
    xml = arm(
        extra='<link name="a"/><link name="b"/>'
        '<joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>'
        '<joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint>'
    )
    assert_rejected(xml, "link 'a'", "is not connected to root link 'base_link': its joints form a cycle")


# --- properties -----------------------------------------------------------------------------


def rotation(quaternion: tuple[float, float, float, float]) -> np.ndarray:
    w, x, y, z = np.array(quaternion) / np.linalg.norm(quaternion)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def inertia_element(
    moments: tuple[float, float, float], quaternion: tuple[float, float, float, float]
) -> str:
    """<inertia> of principal moments [kg·m²] rotated by the quaternion."""
    rot = rotation(quaternion)
    matrix = rot @ np.diag(moments) @ rot.T
    values = {
        "ixx": matrix[0, 0], "ixy": matrix[0, 1], "ixz": matrix[0, 2],
        "iyy": matrix[1, 1], "iyz": matrix[1, 2], "izz": matrix[2, 2],
    }  # fmt: skip
    return "<inertia " + " ".join(f'{k}="{float(v)!r}"' for k, v in values.items()) + "/>"


unit = st.floats(-1.0, 1.0)
quaternions = st.tuples(unit, unit, unit, unit).filter(lambda q: math.hypot(*q) > 0.1)
moments = st.floats(0.1, 10.0)
PROPERTY_SETTINGS = settings(max_examples=60, deadline=None)


@PROPERTY_SETTINGS
@given(mass=st.floats(1e-6, 1e6), a=moments, b=moments, t=st.floats(0.0, 1.0), quaternion=quaternions)
def test_random_valid_inertias_pass(
    mass: float, a: float, b: float, t: float, quaternion: tuple[float, float, float, float]
) -> None:
    """Any positive mass and rotated principal moments |a - b| <= c <= a + b pass."""
    low = max(abs(a - b), 1e-3)
    c = low + t * (a + b - low)
    validate_urdf_string(
        arm(mass=f'<mass value="{mass!r}"/>', inertia=inertia_element((a, b, c), quaternion))
    )


@PROPERTY_SETTINGS
@given(a=moments, b=moments, excess=st.floats(1e-6, 10.0), quaternion=quaternions)
def test_random_inertias_violating_triangle_inequality_fail(
    a: float, b: float, excess: float, quaternion: tuple[float, float, float, float]
) -> None:
    """Rotated principal moments with c > a + b fail on the triangle inequality."""
    c = (a + b) * (1.0 + excess)
    error = rejected(arm(inertia=inertia_element((a, b, c), quaternion)))
    assert error.element == "link 'link2' <inertial><inertia>"
    assert "violate the triangle inequality" in error.reason


@PROPERTY_SETTINGS
@given(mass=st.floats(max_value=0.0, allow_nan=False) | st.sampled_from([math.nan, math.inf, -math.inf]))
def test_random_non_positive_masses_fail(mass: float) -> None:
    error = rejected(arm(mass=f'<mass value="{mass!r}"/>'))
    assert error.element == "link 'link2' <inertial><mass>"
    assert error.reason == f'mass value="{mass!r}" must be a finite number > 0 kg'


# --- why: Pinocchio 4.1 accepts these silently ------------------------------------------------


def test_pinocchio_accepts_negative_mass(capfd: pytest.CaptureFixture[str]) -> None:
    xml = arm(mass='<mass value="-1.0"/>')
    model = pin.buildModelFromXML(xml)
    assert model.inertias[2].mass < 0
    capfd.readouterr()
    assert_rejected(xml, "link 'link2' <inertial><mass>", 'mass value="-1.0" must be a finite number > 0 kg')


def test_pinocchio_drops_inertia_of_non_numeric_mass(capfd: pytest.CaptureFixture[str]) -> None:
    xml = arm(mass='<mass value="abc"/>')
    model = pin.buildModelFromXML(xml)  # no exception
    assert model.inertias[2].mass == 0.0
    np.testing.assert_allclose(model.inertias[2].inertia, np.zeros((3, 3)), atol=0.0)
    assert "not a float" in capfd.readouterr().err  # the only trace, on stderr
    assert_rejected(xml, "link 'link2' <inertial><mass>", 'mass value="abc"')


def test_pinocchio_accepts_non_positive_definite_inertia(capfd: pytest.CaptureFixture[str]) -> None:
    xml = arm(inertia='<inertia ixx="-1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>')
    model = pin.buildModelFromXML(xml)
    assert np.linalg.eigvalsh(model.inertias[2].inertia).min() < 0
    capfd.readouterr()
    assert_rejected(xml, "link 'link2' <inertial><inertia>", "not positive semidefinite")


def test_pinocchio_accepts_zero_axis_giving_singular_mass_matrix(capfd: pytest.CaptureFixture[str]) -> None:
    xml = arm(axis='<axis xyz="0 0 0"/>')
    model = pin.buildModelFromXML(xml)
    data = model.createData()
    mass_matrix = pin.crba(model, data, pin.neutral(model))
    assert mass_matrix[1, 1] == 0.0  # joint2 moves nothing
    capfd.readouterr()
    assert_rejected(xml, "joint 'joint2' <axis>", "nonzero norm")


def test_pinocchio_hides_reason_for_truncated_file(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    text = SHIPPED_URDF.read_text()
    path = tmp_path / "truncated.urdf"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(ValueError) as info:
        pin.buildModelFromUrdf(str(path))
    assert "line" not in str(info.value)  # the reason and line only go to stderr
    assert "line" in capfd.readouterr().err.lower()
    with pytest.raises(InvalidURDFError) as ours:
        validate_urdf_file(path)
    assert "line" in ours.value.reason and "column" in ours.value.reason


# -- the validator and Pinocchio read the same document -----------------------------------------

_ENTITY_MASS = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY m "2.0">]>
<robot name="r"><link name="base"/>
<joint name="j" type="revolute"><parent link="base"/><child link="l"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<link name="l"><inertial><mass value="&m;"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
</robot>
"""


def test_an_entity_defined_mass_is_refused_because_pinocchio_would_drop_it(tmp_path: Path) -> None:
    """Python's parser expands ``&m;`` to 2.0; Pinocchio's does not and silently gives the link no
    inertia (shown below). A DTD or entity declaration is refused, naming the line."""
    path = tmp_path / "entity.urdf"
    path.write_text(_ENTITY_MASS)
    model = pin.buildModelFromUrdf(str(path))
    assert model.inertias[1].mass == 0.0  # the silent loss the refusal prevents
    with pytest.raises(
        InvalidURDFError, match=r"declares a <!DOCTYPE> \(line 2\); expected a URDF without DTD or entities"
    ):
        validate_urdf_file(path)


def test_an_external_entity_is_refused_before_it_is_read(tmp_path: Path) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("1.0")
    doc = _ENTITY_MASS.replace('<!ENTITY m "2.0">', f'<!ENTITY m SYSTEM "file://{secret}">')
    with pytest.raises(InvalidURDFError, match="DOCTYPE"):
        validate_urdf_string(doc)


def test_a_utf16_file_is_refused_naming_the_encoding(tmp_path: Path) -> None:
    path = tmp_path / "u16.urdf"
    path.write_bytes(
        _ENTITY_MASS.replace('<!DOCTYPE robot [<!ENTITY m "2.0">]>\n', "")
        .replace("&m;", "2")
        .encode("utf-16")
    )
    with pytest.raises(InvalidURDFError, match="is UTF-16 encoded; expected UTF-8"):
        validate_urdf_file(path)


def test_a_fifo_and_a_device_are_refused_without_reading(tmp_path: Path) -> None:
    """Reading a FIFO blocks and /dev/zero never ends: both are refused before any read."""
    import os

    fifo = tmp_path / "robot.urdf"
    os.mkfifo(fifo)
    start = time.perf_counter()
    for path in (fifo, Path("/dev/zero")):
        with pytest.raises(InvalidURDFError, match="is not a regular file"):
            validate_urdf_file(path)
    assert time.perf_counter() - start < 5


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('effort="240" ', ""), "effort is missing; URDF requires <limit effort=... velocity=...>"),
        (('velocity="10"', ""), "velocity is missing; URDF requires"),
        (('<robot name="twolink">', "<robot>"), 'has no name; expected <robot name="...">'),
        (('<mass value="10.0"/>', '<mass value="1e308"/>'), "is more than 1e+06 kg"),
    ],
)
def test_what_urdfdom_needs_or_overflows_is_refused_with_a_reason(
    change: tuple[str, str], message: str
) -> None:
    """Pinocchio's parser (urdfdom) requires a limit's effort and velocity and the robot's name,
    and reports their absence only as lines on stderr and "not a valid URDF model"; a mass of
    1e308 kg overflows M(q). Each is refused first, saying why."""
    text = SHIPPED_URDF.read_text()
    assert change[0] in text
    with pytest.raises(InvalidURDFError, match=re.escape(message)):
        validate_urdf_string(text.replace(change[0], change[1], 1))


def test_deep_nesting_is_refused_before_pinocchio_reads_it() -> None:
    deep = "<a>" * 200 + "</a>" * 200
    text = SHIPPED_URDF.read_text().replace("</robot>", deep + "</robot>")
    with pytest.raises(InvalidURDFError, match="nests elements more than 64 deep"):
        validate_urdf_string(text)


def test_a_mass_with_zero_inertia_is_a_point_mass() -> None:
    """mass > 0 and all six inertia entries 0: a point mass (the payload writer's form),
    accepted; Pinocchio's M₂₂ is then exactly m r² (2 kg at r = 0.12 m from joint 2)."""
    import pinocchio as pin

    text = arm(inertia='<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>')
    validate_urdf_string(text)
    model = pin.buildModelFromXML(text)
    M = pin.crba(model, model.createData(), np.zeros(model.nq))
    assert M[1, 1] == pytest.approx(2.0 * 0.12**2, rel=1e-12)
