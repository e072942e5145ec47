"""What a named robot brings beyond its URDF: data, no behaviour.

A :class:`RobotProfile` is attached to every :class:`~twolink_pin.model.RobotModel`. For a
robot of the catalog (:mod:`twolink_pin.model.catalog`) it names the URDF, the parameter
map, the gains its maintainers recommend per law, the friction of its simulated plant, the
initial tracking error, the default trajectory and what its report shows
(:class:`ReportProfile`: the laws, the animated one, figure numbers, the robot's own
sections through a :class:`ReportSections` hook); for any other URDF it is
:func:`generic_profile` (nothing preset: laws derive their gains from the robot).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    import pinocchio as pin

    from twolink_pin.model.parameters import ParameterMap


@dataclass(frozen=True)
class TrajectorySpec:
    """A periodic via-point trajectory, as data (built by :mod:`twolink_pin.trajectory`).

    Exactly one of ``joint_points`` and ``cartesian_points`` is given.

    Attributes:
        times: Via-point times [s], strictly increasing.
        joint_points: Joint positions [rad] at each time, one tuple of nv values each.
        cartesian_points: End-effector positions [m] at each time: ``(x, y)`` for a planar
            2R arm (analytic IK, elbow ``branch``) or ``(x, y, z)`` for any arm.
        branch: Elbow branch of the planar 2R IK: 0 for ``q2 >= 0``, 1 for ``q2 <= 0``.
        period: Repetition period [s]; ``None`` means the via-point span.
    """

    times: tuple[float, ...]
    joint_points: tuple[tuple[float, ...], ...] | None = None
    cartesian_points: tuple[tuple[float, ...], ...] | None = None
    branch: int = 0
    period: float | None = None


class ReportSections(Protocol):
    """Sections a robot adds to its ``twolink-pin report`` (the twolink's: the course
    report's Table 1, Table 2, errata and identification section,
    :class:`twolink_pin.twolink.course_report.CourseReport`). The report calls them in this
    order; arguments are the report's own objects (typed loosely: this module sits below
    the report).
    """

    def steps(self, options: Any, laws: Sequence[str]) -> int:
        """Progress steps :meth:`collect` adds for the report's ``options`` and ``laws`` (the
        laws or variants it runs)."""
        ...

    def submit(self, pool: Any, options: Any, fig_dir: str, laws: Sequence[str]) -> Any:
        """Submit the sections' long tasks to the report's worker ``pool`` (before the
        laws' runs); returns what :meth:`collect` takes (None: nothing submitted)."""
        ...

    def facts(self, robot: Any, via: Any) -> dict[str, Any]:
        """The robot's document's facts (``results.json``'s ``twolink`` entry); ``via``:
        the via points of the robot's default trajectory, None for another trajectory."""
        ...

    def reads(self, laws: Sequence[str]) -> Sequence[str]:
        """The laws (of the report's ``laws``) whose runs :meth:`collect` reads: the report
        collects the sections as soon as those are in, while the other laws still run."""
        ...

    def collect(
        self, pending: Any, robot: Any, options: Any, fig_dir: str, runs: Mapping[str, Any]
    ) -> dict[str, Any] | None:
        """The section built from :meth:`submit`'s tasks and the laws' ``runs`` (law name →
        simulation result; at least those :meth:`reads` names that finished);
        ``results.json``'s ``identification`` entry."""
        ...

    def errata(
        self,
        robot: Any,
        trajectory: Any,
        runs: Mapping[str, Any],
        specs: Mapping[str, str],
        options: Any,
        q0_offset: Any,
        lams: Mapping[str, float],
    ) -> list[dict[str, Any]]:
        """Where the robot's document is wrong or silent (law name → result ``runs``, law
        name → spec ``specs``, law name → λ [1/s] ``lams``)."""
        ...


@dataclass(frozen=True)
class ReportProfile:
    """What ``twolink-pin report`` shows of a robot beyond what every robot gets.

    Attributes:
        laws: The laws the report runs when none are asked for (law specs); ``None``:
            every built-in law.
        animated_law: The law whose run the report animates; ``None`` (or that law not
            run): the first law.
        figure_numbers: Law name (and ``"trajectory"``) → figure kind → the number the
            robot's own document gives that figure (shown in the figures' titles).
        sections: The robot's own sections (:class:`ReportSections`); ``None``: none.
    """

    laws: tuple[str, ...] | None = None
    animated_law: str | None = None
    figure_numbers: Mapping[str, Mapping[str, int]] = field(default_factory=lambda: MappingProxyType({}))
    sections: ReportSections | None = None


@dataclass(frozen=True)
class ArmEffects:
    """What a real arm adds to its rigid bodies, per joint, with where the values come from
    (a plant models them on request: ``--armature arm``, :mod:`twolink_pin.arm_effects`).

    Attributes:
        armature: Rotor inertia reflected through the gearbox [kg·m²] per joint; None: none given.
        damping: Joint damping [N·m·s/rad] per joint; None: none given.
        frictionloss: Dry friction [N·m] per joint (MuJoCo's ``frictionloss``); None: none given.
        source: Where each value comes from, cited (a data sheet, a published model).
    """

    armature: tuple[float, ...] | None = None
    damping: tuple[float, ...] | None = None
    frictionloss: tuple[float, ...] | None = None
    source: str = ""


@dataclass(frozen=True)
class RobotProfile:
    """A robot's name and the defaults the toolkit uses with it.

    Attributes:
        name: Short name (``twolink``, ``ur5``, or a URDF file's stem).
        description: One line for listings.
        parameter_map: Builds the map ``p`` from the Pinocchio model; ``None``: the loader's
            default (all inertial parameters).
        gain_presets: Per law name, gains field → value, used when a law is built on this
            robot without explicit gains (e.g. the course report's gains on the twolink).
        friction: ``(viscous [N·m·s/rad], coulomb [N·m])`` per joint of the plant that
            friction-estimating laws run on; ``None``: no friction.
        q0_offset: Default ``q(0) − q_d(0)`` [rad], one per joint; ``None``: ±
            :data:`DEFAULT_Q0_OFFSET`, alternating in sign (:func:`default_q0_offset`).
        trajectory: The default reference; ``None``: built from the joint limits.
        ee_frame: End-effector frame name; ``None``: ``ee_link`` if present, else the last
            frame on the last joint.
        package_dirs: Folders in which ``package://`` mesh paths are resolved.
        source: Where the URDF comes from (shown by ``twolink-pin robots``).
        locked_joints: Joints held fixed at their ``locked_positions`` (a gripper's
            fingers): the model is Pinocchio's reduced model, their links' masses carried by
            the link they hang from.
        locked_positions: Position of each locked joint [rad or m]; ``None``: 0 clipped to its limits.
        home: A configuration the default trajectory and the viewer start from [rad], one
            per joint of the (reduced) model; ``None``: one the loader chooses near the middle
            of the ranges, away from singularities (:func:`~twolink_pin.model.home.choose_home`).
        acceleration_limits: ``|q̈_j| <=`` these [rad/s²], one per joint of the (reduced)
            model, from the maker's data sheet (a URDF has no acceleration limit); ``None``:
            none (:mod:`twolink_pin.limits`).
        report: What ``twolink-pin report`` shows of this robot (:class:`ReportProfile`).
        repair_inertias: Load the URDF with its triangle-breaking inertias replaced by the nearest
            consistent ones (:mod:`~twolink_pin.model.inertia_repair`).
        free_joints: The joints left free, every other one locked (at its ``locked_positions``
            entry if ``locked_joints`` names it, else 0 clipped to its limits); ``None``: only
            ``locked_joints`` are locked.
        amplitude: The largest swing [rad] of the default reference about home
            (:func:`~twolink_pin.trajectory.defaults.neutral_motion`); ``None``: its default.
        file: The profile file this profile was read from (:mod:`~twolink_pin.model.profile_file`);
            ``None`` for one written in code. Refusals of its values name it.
        home_source: How ``home`` was chosen when the profile gave none (set by the loader:
            :mod:`~twolink_pin.model.home`); ``""`` for a home the profile gives.
        effects: The arm's armature, joint damping and dry friction with their sources
            (:class:`ArmEffects`); ``None``: none given (a URDF's ``<dynamics>`` may give
            damping and friction).
    """

    name: str
    description: str = ""
    parameter_map: Callable[[pin.Model], ParameterMap] | None = None
    gain_presets: Mapping[str, Mapping[str, Any]] = field(default_factory=lambda: MappingProxyType({}))
    friction: tuple[tuple[float, ...], tuple[float, ...]] | None = None
    q0_offset: tuple[float, ...] | None = None
    trajectory: TrajectorySpec | None = None
    ee_frame: str | None = None
    package_dirs: tuple[Path, ...] = ()
    source: str = ""
    locked_joints: tuple[str, ...] = ()
    locked_positions: tuple[float, ...] | None = None
    home: tuple[float, ...] | None = None
    acceleration_limits: tuple[float, ...] | None = None
    report: ReportProfile = field(default_factory=ReportProfile)
    repair_inertias: bool = False
    free_joints: tuple[str, ...] | None = None
    amplitude: float | None = None
    file: Path | None = None
    home_source: str = ""
    effects: ArmEffects | None = None


DEFAULT_Q0_OFFSET = 0.05
"""The initial error ``|q(0) − q_d(0)|`` [rad] of a robot whose profile sets none (a URDF of
yours): a run that starts on its reference would show every law as perfect."""


def default_q0_offset(nv: int) -> tuple[float, ...]:
    """``(+0.05, −0.05, +0.05, ...)`` [rad]: :data:`DEFAULT_Q0_OFFSET`, alternating in sign."""
    return tuple(DEFAULT_Q0_OFFSET * (-1) ** j for j in range(nv))


def generic_profile(path: Path) -> RobotProfile:
    """The profile of a URDF outside the catalog: named after the file, nothing preset."""
    return RobotProfile(name=path.stem, description=f"URDF file {path}", source=str(path))
