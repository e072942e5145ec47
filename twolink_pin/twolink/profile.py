"""The twolink's entry in the robot catalog: ``robots/twolink.toml`` plus what only code can say.

Its profile file holds the data — the URDF, the report's gains, friction, initial offset and via
points (checked against :mod:`twolink_pin.twolink.reference` by the tests); this module adds the
lumped parameter map and the report's own sections, and registers the twolink in
:mod:`twolink_pin.model.catalog` (the package's ``__init__`` imports it).
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path
from types import MappingProxyType

from twolink_pin.model import catalog
from twolink_pin.model.profile import ReportProfile, RobotProfile
from twolink_pin.model.profile_file import read_profile_file
from twolink_pin.twolink import reference
from twolink_pin.twolink.course_report import ANIMATED_LAW, CourseReport
from twolink_pin.twolink.lumped_map import TwoLinkLumpedMap

PROFILE_FILE = "twolink.toml"
"""The twolink's profile file in the package's ``robots`` folder."""


def twolink_urdf_path() -> Path:
    """Path of the shipped ``twolink.urdf`` (works from a checkout and an installed wheel)."""
    return catalog.package_folder() / "twolink.urdf"


@functools.cache
def twolink_entry() -> tuple[Path, RobotProfile]:
    """The twolink's URDF and profile: its profile file, the lumped map and the report's sections."""
    urdf, profile = read_profile_file(catalog.package_folder() / PROFILE_FILE, "twolink")
    return urdf, dataclasses.replace(
        profile,
        parameter_map=TwoLinkLumpedMap,
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


catalog.register("twolink", twolink_entry)
