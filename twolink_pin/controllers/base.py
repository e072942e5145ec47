"""The control-law contract: one class, one file, one method on batch-first arrays.

A law subclasses :class:`Controller`, states its law in the class docstring, declares

* ``name`` — the registry name (``twolink-pin simulate NAME``); defining the class
  registers it in :data:`CONTROLLERS`;
* ``title`` — a short display title;
* ``Gains`` — its gains class (:mod:`twolink_pin.controllers.gains`: defaults and units);
* ``estimates`` — which parameters its internal state ``z`` estimates, in order:
  ``"inertial"`` (the robot's parameter map ``p``) and/or ``"friction"`` (viscous then
  Coulomb coefficient per joint); empty for a law without estimates;
* optionally, state of any other kind (an integrator, a filter): it overrides
  :meth:`Controller.state_variables` (names, units, kinds — after ``super()``'s estimates)
  and :meth:`Controller.initial_state` (the values). Estimates are one case of state: the
  whole of ``z`` is recorded (``SimulationResult.state``), the estimates also as ``p_hat``;

and implements **one** method, :meth:`Controller.compute`, that maps a :class:`LawInput`
(time, state, reference) to a :class:`LawOutput` (torque τ and, for a law with state, ż).
A law that looks ahead declares :meth:`Controller.preview_times` (offsets from now [s]): the
engine then samples the reference there and hands it in :attr:`LawInput.preview`.
A law that plans (the model-predictive law) also declares :meth:`Controller.update_period`
and :meth:`Controller.update`: a discrete update of its state (the new plan) that the engine
makes at those instants.
Every array has a leading run axis: ``q`` is ``(N, nv)`` for N runs advanced together
(N = 1 for a single run); the reference sample is ``(1, nv)`` (the same for every run).
Write the law with numpy broadcasting and it never needs to know N.

The Pinocchio quantities a law needs are asked of the :class:`Terms` object the engine
passes in — it evaluates them for all N runs at once (one ``pin.rnea`` for a single run,
``rneaInParallel`` over a ``ModelPool`` for a batch): the model term, the regressor, and
``M̂``, ``ĝ``, ``Ĉ q̇ + ĝ``, ``M̂⁻¹ b`` and a frame's pose, Jacobian and ``J̇ q̇`` on the
law's believed model. A law never calls Pinocchio itself.

Notation (report): ``e = q − q_d``, ``ė = q̇ − q̇_d``, ``s = ė + λ e``,
``q̇_r = q̇_d − λ e``, ``q̈_r = q̈_d − λ ė``.
"""

from __future__ import annotations

import abc
import dataclasses
from typing import Any, ClassVar, Generic, NamedTuple, TypeVar

import numpy as np

from twolink_pin.controllers.gains import Gains as GainsBase
from twolink_pin.controllers.gains import check_width, gain_spec, runs_of
from twolink_pin.controllers.law_io import LawInput, LawOutput, Terms
from twolink_pin.controllers.matrix_gains import as_matrix
from twolink_pin.controllers.relaxation import RunRelaxation
from twolink_pin.errors import ControllerSpecError, InvalidParameterError
from twolink_pin.model import RobotModel

ESTIMATES = ("inertial", "friction")
"""Kinds of parameters a law may estimate, in the order they appear in ``z``."""
FRICTION_UNITS = {"viscous": "N·m·s/rad", "coulomb": "N·m"}
"""Units of the friction coefficients."""


class StateVariable(NamedTuple):
    """One entry of a law's internal state ``z`` (see :meth:`Controller.state_variables`)."""

    name: str
    """Short name, e.g. ``"p1"`` or ``"∫e1"``."""
    unit: str
    """SI unit, e.g. ``"kg·m²"`` or ``"rad·s"``."""
    kind: str
    """``"inertial"`` or ``"friction"`` for an estimate (:data:`ESTIMATES`), else the law's
    own word (e.g. ``"integral"``, ``"filter"``)."""


def check_state_declaration(controller: Any) -> None:
    """Refuse a law whose state declaration is wrong, when it is built: a name empty or given
    twice in :meth:`Controller.state_variables`, or an :meth:`Controller.initial_state` whose
    size is not the number of entries declared. Its :meth:`Controller.update_period` is asked
    here too, so that a hook that raises does so while the law is built (user code contained:
    the law, its file and line named), not inside the engine.

    Raises:
        InvalidParameterError: naming the law, the entry and what was expected.
    """
    law = f"law {getattr(controller, 'name', type(controller).__name__)!r}"
    variables = tuple(controller.state_variables())
    names = [getattr(v, "name", None) for v in variables]
    for i, name in enumerate(names):
        if not isinstance(name, str) or not name.strip():
            raise InvalidParameterError(
                f"{law}: state_variables()[{i}].name", name, "a non-empty name (each entry of z is named)"
            )
    twice = [n for n in dict.fromkeys(names) if names.count(n) > 1]
    if twice:
        raise InvalidParameterError(
            f"{law}: state_variables()",
            f"{twice[0]!r} at entries {[i for i, n in enumerate(names) if n == twice[0]]}",
            "each state entry named once",
        )
    z0 = np.asarray(controller.initial_state())
    if z0.ndim not in (1, 2) or z0.shape[-1] != len(variables):
        raise InvalidParameterError(
            f"{law}: initial_state()",
            f"shape {z0.shape}",
            f"(nz,) or (N, nz) with nz = {len(variables)}, the entries state_variables() declares "
            f"({', '.join(map(str, names)) or 'none'})",
        )
    controller.update_period()  # its value is checked against the step by the engine


G = TypeVar("G", bound=GainsBase)
"""The gains class of a law (``Controller[PDGains]``); a user's law may leave it out."""

CONTROLLERS: dict[str, type[Controller[Any]]] = {}
"""Every registered law by name: the built-in ones, then those defined later (a user's
file, a package's entry point ``twolink_pin.controllers``), in definition order."""


def _register(cls: type[Controller[Any]]) -> None:
    name = cls.__dict__["name"]
    if not isinstance(name, str) or not name or name.strip() != name or " " in name:
        raise ControllerSpecError(
            repr(name), f"{cls.__qualname__}.name must be a non-empty name without spaces"
        )
    for attr in ("title", "Gains"):
        if not hasattr(cls, attr):
            raise ControllerSpecError(name, f"{cls.__qualname__} must declare {attr!r}")
    if not (
        isinstance(cls.Gains, type)
        and issubclass(cls.Gains, GainsBase)
        and dataclasses.is_dataclass(cls.Gains)
    ):
        raise ControllerSpecError(name, f"{cls.__qualname__}.Gains must be a dataclass subclassing Gains")
    if cls.Gains is not GainsBase and "__dataclass_fields__" not in cls.Gains.__dict__:
        # a subclass of a dataclass without @dataclass of its own: its gain(...) fields would stay
        # class attributes (dataclasses.Field objects) and fail at t = 0
        raise ControllerSpecError(
            name,
            f"{cls.__qualname__}.Gains ({cls.Gains.__qualname__}) must be a dataclass: decorate it with "
            "@dataclass(frozen=True, eq=False)",
        )
    unknown = [e for e in cls.estimates if e not in ESTIMATES]
    if unknown or len(set(cls.estimates)) != len(cls.estimates):
        raise ControllerSpecError(
            name, f"estimates must be distinct entries of {ESTIMATES}, got {cls.estimates}"
        )
    existing = CONTROLLERS.get(name)
    if existing is not None and (existing.__module__, existing.__qualname__) != (
        cls.__module__,
        cls.__qualname__,
    ):
        raise ControllerSpecError(
            name,
            f"the name is taken by {existing.__module__}.{existing.__qualname__}; give the class another name",
        )
    CONTROLLERS[name] = cls


class Controller(abc.ABC, Generic[G]):
    """Base class of every control law (see the module docstring for the contract).

    Args:
        robot: The arm the law is designed for: its model gives the model term and the
            regressor's parameter map; its profile may preset the gains.
        gains: The law's gains; default: the robot's preset for this law, else the
            ``Gains`` defaults, per-joint values derived from the robot where ``None``.
        model_parameters: The parameters ``p`` (the robot's map) the law's model uses,
            shape (n_p,) or one row per run (N, n_p); default: the robot's own. A
            controller with a parameter error believes ``p ⊙ (1 + δ)``.
    """

    name: ClassVar[str]
    """Registry name, e.g. ``"pd"``."""
    title: ClassVar[str]
    """Display title, e.g. ``"PD + model feedforward"``."""
    Gains: ClassVar[type[Any]]
    """The law's gains class (a :class:`~twolink_pin.controllers.gains.Gains` dataclass)."""
    estimates: ClassVar[tuple[str, ...]] = ()
    """Parameters held in ``z``: a subsequence of :data:`ESTIMATES`."""
    task_space: ClassVar[bool] = False
    """True for a law on the end effector's pose: the engine fills ``LawInput.x_des``,
    ``R_des``, ``twist_des`` and ``accel_des`` for it, and the commands show its task-space
    errors (mm, deg)."""
    force_control: ClassVar[bool] = False
    """True for a law that controls a contact force (it reads ``LawInput.contact.force_des``):
    it runs only against a scene's surface, and only such a law takes a force reference."""

    def __init_subclass__(cls, register: bool = True, **kwargs: Any) -> None:
        """Register the class under its ``name`` (``class X(Controller, register=False)``
        for a law that is used directly but never named, e.g. in a test)."""
        super().__init_subclass__(**kwargs)
        if register and "name" in cls.__dict__ and not getattr(cls.compute, "__isabstractmethod__", False):
            _register(cls)

    def __init__(
        self,
        robot: RobotModel,
        gains: G | None = None,
        *,
        model_parameters: np.ndarray | None = None,
    ) -> None:
        if not isinstance(robot, RobotModel):
            raise InvalidParameterError(
                "robot", type(robot).__name__, "a RobotModel (twolink_pin.load_robot)"
            )
        self.robot = robot
        if gains is None:
            presets = dict(robot.gain_presets.get(self.name, {}))
            valid = set(self.Gains.field_names())
            presets = {k: v for k, v in presets.items() if k in valid}
            gains = self.Gains(**presets)
        if not isinstance(gains, self.Gains):
            raise InvalidParameterError(
                "gains", type(gains).__name__, f"an instance of {self.Gains.__name__}"
            )
        self.gains: G = self._resolve(gains)
        """The law's gains, validated: floats or read-only arrays (per joint, per run)."""
        self.model_parameters = self._check_parameters(model_parameters)

    # -- declarations derived from the class and the robot -----------------------------

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of the estimated parameters, in the order of ``z``."""
        return self.estimated_names(self.robot)

    @classmethod
    def estimated_names(cls, robot: RobotModel) -> tuple[str, ...]:
        """Names of the parameters the law estimates on ``robot`` (:attr:`parameter_names`)."""
        names: list[str] = []
        for kind in cls.estimates:
            if kind == "inertial":
                names += robot.parameter_map.names
            else:
                n = robot.nv
                names += [f"V{j + 1}" for j in range(n)] + [f"C{j + 1}" for j in range(n)]
        return tuple(names)

    @classmethod
    def gain_widths(cls, robot: RobotModel) -> dict[str, tuple[int, str]]:
        """For each ``per`` of a gain: how many values it has on ``robot`` and what they are for
        (``{"joint": (nv, "per joint, nv = 2"), ...}``)."""
        names = cls.estimated_names(robot)
        return {
            "joint": (robot.nv, f"per joint, nv = {robot.nv}"),
            "estimate": (len(names), f"per estimated parameter: {names}"),
            "axis": (3, "per world axis x, y, z"),
        }

    @property
    def parameter_units(self) -> tuple[str, ...]:
        """SI unit of each estimated parameter."""
        units: list[str] = []
        for kind in self.estimates:
            if kind == "inertial":
                units += self.robot.parameter_map.units
            else:
                units += [FRICTION_UNITS["viscous"]] * self.robot.nv + [
                    FRICTION_UNITS["coulomb"]
                ] * self.robot.nv
        return tuple(units)

    @property
    def parameter_kinds(self) -> tuple[str, ...]:
        """``"inertial"`` or ``"friction"`` for each estimated parameter."""
        kinds: list[str] = []
        for kind in self.estimates:
            size = self.robot.parameter_map.size if kind == "inertial" else 2 * self.robot.nv
            kinds += [kind] * size
        return tuple(kinds)

    def state_variables(self) -> tuple[StateVariable, ...]:
        """What ``z`` holds, in order: the estimates (:attr:`parameter_names`) by default.

        A law with other state overrides this and appends its entries to ``super()``'s
        (and overrides :meth:`initial_state` to give their values)::

            def state_variables(self):
                return super().state_variables() + tuple(
                    StateVariable(f"∫e{j + 1}", "rad·s", "integral") for j in range(self.robot.nv)
                )
        """
        return tuple(
            StateVariable(name, unit, kind)
            for name, unit, kind in zip(
                self.parameter_names, self.parameter_units, self.parameter_kinds, strict=True
            )
        )

    @property
    def state_size(self) -> int:
        """``nz``: size of the law's internal state."""
        return len(self.state_variables())

    @property
    def estimate_columns(self) -> np.ndarray:
        """Indices in ``z`` of the estimated parameters (kinds in :data:`ESTIMATES`)."""
        kinds = [v.kind for v in self.state_variables()]
        return np.array([i for i, kind in enumerate(kinds) if kind in ESTIMATES], dtype=int)

    @property
    def runs(self) -> int | None:
        """Number of runs this object's per-run gains or parameters describe (their leading
        axis), or None when it holds one value set for every run."""
        counts = {runs_of(v) for v in self.gains.values().values()}
        if isinstance(self.model_parameters, np.ndarray) and self.model_parameters.ndim == 2:
            counts.add(int(self.model_parameters.shape[0]))
        counts.discard(None)
        if len(counts) > 1:
            raise InvalidParameterError(
                "gains", sorted(counts), "per-run values with one number of runs N (the leading axis)"
            )
        return counts.pop() if counts else None

    @classmethod
    def takes(cls, gain_name: str) -> bool:
        """Whether the law's gains have a field ``gain_name`` (e.g. ``"lam"``)."""
        return gain_name in cls.Gains.field_names()

    def believed_parameters(self) -> np.ndarray:
        """The parameters ``p`` of the law's model: ``model_parameters`` or the robot's."""
        return self.model_parameters if self.model_parameters is not None else np.asarray(self.robot.p)

    def initial_state(self) -> np.ndarray:
        """``z(0)``, shape (nz,) or one row per run (N, nz); zeros unless overridden."""
        return np.zeros(self.state_size)

    def update_period(self) -> float | None:
        """Time [s] between the law's discrete updates of its state (:meth:`update`: a
        planning law's replans), from t = 0; ``None`` (the default): the law has none.
        The engine calls :meth:`update` at every multiple of this period, which must be a
        multiple of the simulation step."""
        return None

    def update(self, x: LawInput, terms: Terms) -> np.ndarray:
        """The law's new state ``z``, shape (N, nz), at an update instant (every
        :meth:`update_period` seconds): what a planning law does when it replans (its plan
        and warm start are its state, recorded like any state). Called before
        :meth:`compute` at that instant, with the measured state and the state so far; between
        updates ``z`` moves only by the ``dz`` :meth:`compute` returns (zeros for a plan)."""
        raise NotImplementedError(f"{type(self).__name__} declares an update period but no update()")

    def preview_times(self) -> np.ndarray | None:
        """Offsets ``s_j ≥ 0`` [s] from now at which the law wants the reference at every
        evaluation (a planning law: its knots), shape (P,), fixed for the run; ``None`` (the
        default): none. The engine samples the trajectory at ``t + s_j`` for every run of a
        batch at once and hands the samples in :attr:`LawInput.preview`."""
        return None

    def run_failure(self, run: int) -> str | None:
        """Why the law gave up run ``run`` of the batch it computes, or ``None`` (the default).

        A law that cannot go on with one of its N runs (a planning law whose problem has no
        solution for that run) sets that run's state ``z`` (or its torque) to NaN in
        :meth:`update` (or :meth:`compute`) and says why here: the engine ends that run at that
        time with this text, as it ends a diverged one, and the other runs go on. A single run
        ends with an error naming the law, the time and this text."""
        return None

    def run_relaxations(self, run: int) -> RunRelaxation | None:
        """Where and by how much the law relaxed limits it could not all keep in run ``run``
        (:class:`~twolink_pin.controllers.relaxation.RunRelaxation`), or ``None`` (the
        default: it relaxed none, or never relaxes). Read after the run, into its result."""
        return None

    def scaled_gains(self) -> dict[str, Any]:
        """Values for the per-joint or per-estimate gains left ``None``, derived from the
        robot (override in a law whose gains default to ``None``)."""
        return {}

    # -- the law ------------------------------------------------------------------------

    @abc.abstractmethod
    def compute(self, x: LawInput, terms: Terms) -> LawOutput:
        """The law: torque [N·m] (and ż) for every run.

        Args:
            x: Time, state and reference sample, batch-first (see :class:`LawInput`).
            terms: The engine's Pinocchio terms for the N runs (see :class:`Terms`).

        Returns:
            ``LawOutput(tau)`` with ``tau`` of shape (N, nv), plus ``dz`` of shape
            (N, nz) for a law with state.
        """

    # -- internals ----------------------------------------------------------------------

    def _resolve(self, gains: G) -> G:
        missing = [name for name, value in gains.values().items() if value is None]
        if missing:
            derived = self.scaled_gains()
            absent = [name for name in missing if name not in derived]
            if absent:
                raise InvalidParameterError(
                    f"gains.{absent[0]}", None, f"a value: {type(self).__name__} derives no default for it"
                )
            gains = dataclasses.replace(gains, **{name: derived[name] for name in missing})
        matrices = {}
        widths = self.gain_widths(self.robot)
        for f in dataclasses.fields(gains):
            spec = gain_spec(f)
            value = getattr(gains, f.name)
            if spec.per == "scalar":
                continue
            width, what = widths[spec.per]
            if spec.matrix and value is not None:
                value = matrices[f.name] = as_matrix(value, width, f.name, spec.unit)
            check_width(f.name, value, width, what)
        return dataclasses.replace(gains, **matrices) if matrices else gains

    def _check_parameters(self, p: Any) -> np.ndarray | None:
        if p is None:
            return None
        size = self.robot.parameter_map.size
        try:
            array = np.array(p, dtype=float)
        except (TypeError, ValueError):
            raise InvalidParameterError(
                "model_parameters", p, f"{size} numbers {self.robot.parameter_map.names}"
            ) from None
        if array.shape[-1:] != (size,) or array.ndim not in (1, 2) or not np.all(np.isfinite(array)):
            raise InvalidParameterError(
                "model_parameters",
                array.tolist() if array.size <= 24 else f"shape {array.shape}",
                f"{size} finite values {self.robot.parameter_map.names}, or one row of them per run",
            )
        array.setflags(write=False)
        return array

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} on {self.robot.name}: {self.gains.describe()}>"
