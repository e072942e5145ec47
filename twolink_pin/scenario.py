"""A law and the plant it drives (:class:`Scenario`), and the law's half of building one
(:func:`make_controller`).

:meth:`twolink_pin.run_spec.RunSpec.build` is the one place a run is assembled: the law from
:func:`make_controller`, its plant from :meth:`twolink_pin.plant_options.PlantOptions.plant`.
A friction-estimating law believes its robot's profile friction (the twolink: the report's
V = (0.4, 0.2) N·m·s/rad, C = (0.2, 0.1) N·m; its estimates start from
``friction_initial_estimate`` × it). Nothing here knows a law by name: what a law
estimates and which gains it has, its class declares.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any, NamedTuple

from twolink_pin.controllers import Controller, load_controller
from twolink_pin.controllers.base import check_state_declaration
from twolink_pin.controllers.gains import check_count, spec_of
from twolink_pin.dynamics import Friction
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel
from twolink_pin.plant import Plant
from twolink_pin.user_code import guarded


class Scenario(NamedTuple):
    """A controller and the plant it drives."""

    controller: Controller
    """The control law."""
    plant: Plant
    """The simulated arm."""


def law_class(law: str | type[Controller]) -> type[Controller]:
    """A law class from a class, a registered name, ``file.py:Class`` or ``module:Class``."""
    if isinstance(law, type) and issubclass(law, Controller):
        return law
    if isinstance(law, str):
        return load_controller(law)
    raise InvalidParameterError(
        "controller", law, "a Controller subclass or a name / file.py:Class / module:Class"
    )


def builtin_laws(force_control: bool = False) -> tuple[str, ...]:
    """Names of the laws twolink-pin defines (not a user's nor a package's), in registry order:
    what ``compare`` and ``report`` run when no law is named; those that control a contact
    force (:attr:`~twolink_pin.controllers.Controller.force_control`) only with ``force_control``
    (a run against a surface with a force reference: they run nowhere else)."""
    from twolink_pin.controllers import CONTROLLERS

    return tuple(
        n
        for n, cls in CONTROLLERS.items()
        if cls.__module__.startswith("twolink_pin.controllers.") and (force_control or not cls.force_control)
    )


def _reference(cls: type[Controller]) -> str:
    """How a law is named in an error about its code: its name, and its class in the user's
    file (never the module name a law file is imported under)."""
    try:
        where = inspect.getsourcefile(cls) or ""
    except TypeError:
        where = ""
    return (
        f"{getattr(cls, 'name', cls.__qualname__)} ({cls.__qualname__} in {where})"
        if where
        else str(cls.name)
    )


def make_controller(
    law: str | type[Controller],
    robot: RobotModel,
    *,
    lam: float | None = None,
    gains: Mapping[str, Any] | None = None,
    friction: Friction | None = None,
    model_parameters: Any = None,
) -> Controller:
    """The law on ``robot`` with its default gains (the robot's presets) over ``gains``: the
    law's half of :meth:`~twolink_pin.run_spec.RunSpec.build` (built once per run).

    Args:
        law: The law (class, registered name, ``file.py:Class`` or ``module:Class``).
        robot: The arm (the law's nominal model).
        lam: ``λ`` [1/s] for a law whose gains have ``lam``; refused for one without.
        gains: Other gains by field name (one value, one per joint, ...), over the defaults.
        friction: The friction a friction-estimating law believes (ignored by the others).
        model_parameters: The parameters the law's model believes (see
            :class:`~twolink_pin.controllers.Controller`); one row per run for a batch.

    Raises:
        InvalidParameterError: ``lam`` or a gain the law does not have.
        ControllerSpecError: no such law, or it could not be built.
    """
    cls = law_class(law)
    changes: dict[str, Any] = dict(gains or {})
    if lam is not None:
        if not cls.takes("lam"):
            raise InvalidParameterError(
                "lambda",
                lam,
                f"a law with a λ gain; '{cls.name}' has none (its gains: {', '.join(cls.Gains.field_names())})",
            )
        changes["lam"] = lam
    unknown = [k for k in changes if k not in cls.Gains.field_names()]
    if unknown:
        raise InvalidParameterError(
            "gain", unknown[0], f"one of the gains of '{cls.name}': {', '.join(cls.Gains.field_names())}"
        )
    widths = cls.gain_widths(robot)
    for name, value in changes.items():  # the count of numbers before their values
        spec = spec_of(cls.Gains, name)
        if spec.per != "scalar":
            check_count(name, value, spec, *widths[spec.per])
    presets = {k: v for k, v in robot.gain_presets.get(cls.name, {}).items() if k in cls.Gains.field_names()}
    reference = _reference(cls)
    timed = not cls.__module__.startswith("twolink_pin.")  # user code: under --timeout too
    with guarded(
        reference, f"building its gains {cls.Gains.__name__}", timed=timed
    ):  # a user's gains class's checks
        gains_obj = cls.Gains(**{**presets, **changes})
    kwargs: dict[str, Any] = {}
    if "friction" in cls.estimates:
        kwargs["friction"] = friction
    with guarded(reference, f"building it on {robot.name}", timed=timed):  # its __init__, scaled_gains, state
        controller = cls(robot, gains_obj, model_parameters=model_parameters, **kwargs)
        check_state_declaration(controller)
    return controller
