"""Several runs side by side (``compare``, ``report``): every variant's :class:`Row` — its spec, its law
and plant — built by :func:`build_rows` before any of them runs, so that a bad gain of the third
row, or a step beyond its integrator's bound, is refused before the first runs."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, NamedTuple

from twolink_pin.arm_effects import refuse_idle
from twolink_pin.errors import InvalidParameterError
from twolink_pin.law_variant import Variant
from twolink_pin.model import RobotModel
from twolink_pin.run_spec import RunSpec
from twolink_pin.scenario import Scenario
from twolink_pin.simulation.step_check import CheckTimeout, require_stable_step

if TYPE_CHECKING:
    from twolink_pin.identification import IdentifiedParameters
    from twolink_pin.trajectory import Trajectory


class Row(NamedTuple):
    """One row of several runs (``compare``, ``report``): a variant, its spec and its law and plant."""

    variant: Variant
    """The law and its own settings, as given."""
    spec: RunSpec
    """Its run: the shared spec for its law (:meth:`RunSpec.for_law`), its settings over it."""
    scenario: Scenario
    """Its law and plant, built once (:meth:`RunSpec.build`)."""


def build_rows(
    shared: RunSpec,
    variants: Sequence[Variant],
    robot: RobotModel,
    read: Callable[[RunSpec], IdentifiedParameters | None] | None = None,
    trajectory: Trajectory | None = None,
) -> dict[str, Row]:
    """Every variant's run built before any runs, keyed by its row's name
    (:attr:`~twolink_pin.law_variant.Variant.key`): a bad gain of the third law is refused
    before the first runs, naming its row (``pd@kp=1,2,3: kp = …``).

    Args:
        shared: The spec the variants share (``law`` None).
        variants: The rows, in order.
        robot: The arm.
        read: Reads a spec's parameter file (default :meth:`RunSpec.read_parameters`); each
            file is read once.
        trajectory: The reference the rows will run: each row's step is then checked against
            the fastest mode of its start (:mod:`~twolink_pin.simulation.step_check`), before
            any row runs.

    Raises:
        InvalidParameterError: a value a law refuses, named ``ROW: NAME``.
        StepTooLargeError: a row's step beyond the integrator's bound, named ``ROW: --dt``.
    """
    files: dict[str, IdentifiedParameters | None] = {}
    rows: dict[str, Row] = {}
    for variant in variants:
        spec = shared.for_law(variant)
        if spec.parameters is not None and spec.parameters not in files:
            files[spec.parameters] = read(spec) if read is not None else spec.read_parameters(robot)
        try:
            if variant.plant:  # its own plant options: refused where they would do nothing
                refuse_idle(spec.plant, robot, spec.simulation.method)
            scenario = spec.build(robot, None if spec.parameters is None else files[spec.parameters])
            if trajectory is not None:
                with contextlib.suppress(
                    CheckTimeout
                ):  # a law that never returns: its own run fails, the others go on
                    require_stable_step(scenario.controller, scenario.plant, trajectory, spec.simulation)
        except InvalidParameterError as exc:
            raise type(exc)(f"{variant.key}: {exc.name}", exc.value, exc.expected) from None
        rows[variant.key] = Row(variant, spec, scenario)
    return rows
