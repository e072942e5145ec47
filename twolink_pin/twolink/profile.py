"""The twolink's entry in the robot catalog: its URDF, the lumped map, the report's defaults.

Importing this module registers the twolink in :mod:`twolink_pin.model.catalog` (the
package's ``__init__`` does).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from types import MappingProxyType

from twolink_pin.model import catalog
from twolink_pin.model.profile import ArmEffects, ReportProfile, RobotProfile, TrajectorySpec
from twolink_pin.twolink import reference
from twolink_pin.twolink.course_report import ANIMATED_LAW, CourseReport
from twolink_pin.twolink.lumped_map import TwoLinkLumpedMap


def twolink_urdf_path() -> Path:
    """Path of the shipped ``twolink.urdf`` (works from a checkout and an installed wheel)."""
    return Path(str(resources.files("twolink_pin.robots").joinpath("twolink.urdf")))


TWOLINK = RobotProfile(
    name="twolink",
    description="the course report's 2-link planar arm (horizontal, p = (3.4, 0.4, 0.3) kg·m²)",
    parameter_map=TwoLinkLumpedMap,
    gain_presets=MappingProxyType({k: MappingProxyType(v) for k, v in reference.REPORT_GAINS.items()}),
    friction=reference.REPORT_FRICTION,
    q0_offset=reference.Q0_OFFSET,
    trajectory=TrajectorySpec(
        times=reference.REPORT_TIMES, cartesian_points=reference.REPORT_VIA_XY, branch=0
    ),
    ee_frame="ee_link",
    effects=ArmEffects(
        armature=reference.ARMATURE,
        damping=reference.REPORT_FRICTION[0],
        frictionloss=reference.REPORT_FRICTION[1],
        source="armature: the MuJoCo Menagerie's Panda (franka_emika_panda/panda.xml), the report giving no "
        "drive data; damping and dry friction: the report's viscous V and Coulomb C friction",
    ),
    source="robots/twolink.urdf (this package)",
    report=ReportProfile(
        laws=reference.REPORT_CONTROLLERS,
        animated_law=ANIMATED_LAW,
        figure_numbers=MappingProxyType(
            {k: MappingProxyType(v) for k, v in reference.REPORT_FIGURES.items()}
        ),
        sections=CourseReport(),
    ),
)
"""The twolink's profile: the report's gains, friction, initial offset, via points and what
its report shows (the report's five laws, its figure numbers, its sections)."""

catalog.register("twolink", lambda: (twolink_urdf_path(), TWOLINK))
