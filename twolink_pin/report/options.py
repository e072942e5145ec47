"""What the report runs: :class:`ReportOptions` (a :class:`~twolink_pin.run_spec.RunSpec`
and the report's own options beside it)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from twolink_pin.errors import InvalidParameterError
from twolink_pin.openmp import available_cores
from twolink_pin.run_spec import RunSpec

MAX_WORKERS = 64
"""Largest number of worker processes (more than the runs is never used)."""


@dataclass(frozen=True)
class ReportOptions:
    """What the report runs.

    Attributes:
        run: The runs' common description (:class:`~twolink_pin.run_spec.RunSpec`, shared by
            the laws: each law's own with :meth:`~twolink_pin.run_spec.RunSpec.for_law`):
            simulation settings, λ of the laws that have one, per-law gains, the plant, an
            identified-parameter file (``p0``: the estimates of the laws that estimate start
            there; ``model``: every law's model believes it).
        robot: A catalog name or a URDF path; None for the twolink.
        payload: End-effector payload [kg].
        controllers: The laws to run (names, ``file.py:Class``, ``module:Class``); None for
            the course report's five on the twolink, every built-in law elsewhere.
        workers: Processes for the runs and figures (1: in this process), 1 to 64; None
            (default): the cores this process may use (``os.sched_getaffinity``; 2 on a
            2-core machine), at most 64.
        animation: Whether to write the self-contained animation.
        identification: Whether the twolink's report has its identification section (beside
            Fig. 27: the adaptive law along two excitations and an identification from a
            logged 2-kHz run; about a third of the report's CPU time, docs/performance.md).
        limits_section: Whether the report has its section "The reference within the limits"
            (:mod:`twolink_pin.report.within_limits`: the reference, its time-optimal
            retiming and the minimum-effort trajectory, the laws tracking each; about
            a tenth of the report's CPU time, docs/performance.md).
        sim_to_sim: Whether the report has its section "Sim-to-sim" (:mod:`twolink_pin.report.sim_to_sim`:
            each law on the Pinocchio plant and on MuJoCo with no effect and with the arm's effects;
            short runs of one period).
        sim_to_sim_all: Whether every law of that section has every row: the no-effect check
            and each effect alone too (35 runs on the twolink, about a fifth of the report's CPU
            time); default False: the report's first law only, the others on Pinocchio and with
            every effect (15 runs; docs/mujoco.md).
        trajectory: A trajectory file (:func:`~twolink_pin.trajectory.read_trajectory_file`)
            to track instead of the robot's default; the twolink's sections about the
            report's own trajectory (Table 1, the printed coefficients) then still describe
            the report's.
        repair_inertias: Load the robot with its triangle-breaking inertias repaired
            (``--repair-inertias``; None: the profile's choice).
    """

    run: RunSpec = field(default_factory=lambda: RunSpec(shared=True))
    robot: str | None = None
    payload: float = 0.0
    controllers: tuple[str, ...] | None = None
    workers: int | None = None
    animation: bool = True
    identification: bool = True
    limits_section: bool = True
    trajectory: str | None = None
    repair_inertias: bool | None = None
    sim_to_sim: bool = True
    sim_to_sim_all: bool = False

    def load_robot(self) -> Any:
        """The robot these options name (a :class:`~twolink_pin.model.RobotModel`), loaded here."""
        from twolink_pin.controllers.loading import check_profile_gains
        from twolink_pin.model import load_robot

        robot = load_robot(self.robot, payload=self.payload, repair_inertias=self.repair_inertias)
        check_profile_gains(robot)
        return robot

    def __post_init__(self) -> None:
        if self.workers is None:
            object.__setattr__(self, "workers", min(available_cores(), MAX_WORKERS))
        if not (
            isinstance(self.workers, int)
            and not isinstance(self.workers, bool)
            and 1 <= self.workers <= MAX_WORKERS
        ):
            raise InvalidParameterError("workers", self.workers, f"a whole number from 1 to {MAX_WORKERS}")
        if not isinstance(self.run, RunSpec):
            raise InvalidParameterError("run", type(self.run).__name__, "a RunSpec")
        if not self.run.shared:  # one description for several laws: λ and p0 go where they apply
            object.__setattr__(self, "run", replace(self.run, shared=True))
