"""An arm's equations of motion in closed form: :func:`derive_equations` and its result.

    M(q) q̈ + C(q, q̇) q̇ + g(q) = Y(q, q̇, q̈) β = τ

with every term a SymPy expression in the joint coordinates ``q1..qn`` [rad or m], the
rates ``dq1..dqn``, the accelerations ``ddq1..ddqn``, the **base parameters**
``beta1..betar`` (each defined as a combination of the links' masses ``m_j``, first moments
``mcx_j, mcy_j, mcz_j`` and inertias ``Ixx_j .. Izz_j`` about the joint frame's origin, and the
lengths ``l{j}{x|y|z}``), the lengths and the gravity ``g`` [m/s²]. The numbers of the arm
(β, the lengths, g) ride along, so ``Y β`` is the arm's inverse dynamics.

The derivation (:mod:`~twolink_pin.symbolic.derivation`) is cached per kinematic content
(:mod:`~twolink_pin.symbolic.cache`); building the readable expressions from it takes
milliseconds to seconds (:mod:`~twolink_pin.symbolic.readable`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from twolink_pin.arrays import readonly
from twolink_pin.errors import require_type
from twolink_pin.model.base_parameters import body_name
from twolink_pin.model.parameters import BODY_PARAMETER_NAMES, BODY_PARAMETER_UNITS, inertial_parameters
from twolink_pin.symbolic import cache
from twolink_pin.symbolic.derivation import Derivation, derive
from twolink_pin.symbolic.readable import by_parameter, poly_expr, to_expr
from twolink_pin.symbolic.skeleton import Skeleton, skeleton_of
from twolink_pin.symbolic.support import check_model, first_joints

if TYPE_CHECKING:
    import pinocchio as pin

    from twolink_pin.model import RobotModel

ZERO_PARAMETER = 1e-12
"""A base parameter whose value is at most this (its unit) is 0 in this arm: its terms are
left out of what is shown (:meth:`Equations.shown`), never out of the formulas."""


@dataclass(frozen=True)
class Equations:
    """The equations of motion of one arm (module docstring); build with :func:`derive_equations`."""

    robot: str
    """The robot's name (catalog name or URDF stem)."""
    joint_names: tuple[str, ...]
    kinds: tuple[str, ...]
    """Each joint's kind: ``revolute`` or ``prismatic``."""
    q: tuple[Any, ...]
    """Joint coordinates ``q1..qn`` [rad or m] (SymPy symbols)."""
    dq: tuple[Any, ...]
    """Rates ``dq1..dqn`` (q̇) [rad/s or m/s]."""
    ddq: tuple[Any, ...]
    """Accelerations ``ddq1..ddqn`` (q̈)."""
    w: tuple[Any, ...]
    """The reference rate ``w1..wn`` of :attr:`Y_reference` (Slotine–Li's q̇_r)."""
    beta: tuple[Any, ...]
    """The base parameters ``beta1..betar``."""
    beta_definitions: tuple[Any, ...]
    """Each β as a combination of the standard parameters and the lengths."""
    beta_units: tuple[str, ...]
    beta_values: np.ndarray = field(repr=False)
    """β of this arm (its URDF's inertias, payload included), shape (r,)."""
    standard: tuple[Any, ...] = field(repr=False)
    """The standard parameters ``m1, mcx1, .., Izz1, m2, ..`` (10 per body, Pinocchio's order)."""
    standard_names: tuple[str, ...] = field(repr=False)
    """Each standard parameter as ``link.name`` (``link2.mcx``), the names of
    :class:`~twolink_pin.model.base_parameters.BaseParameterMap`."""
    standard_values: np.ndarray = field(repr=False)
    """π of this arm, shape (10 n,)."""
    lengths: dict[str, float] = field(repr=False)
    """Each length symbol's value [m]."""
    length_meanings: dict[str, str] = field(repr=False)
    gravity: float
    """g [m/s²] (its direction is in the formulas)."""
    M: Any = field(repr=False)
    """``M(q)``, n × n (a ``sympy.Matrix``)."""
    C: Any = field(repr=False)
    """``C(q, q̇)`` by the Christoffel symbols, n × n."""
    g: Any = field(repr=False)
    """``g(q)``, n × 1."""
    Y: Any = field(repr=False)
    """``Y(q, q̇, q̈)`` with ``Y β = M q̈ + C q̇ + g``, n × r."""
    Y_reference: Any = field(repr=False)
    """``Y(q, q̇, w, q̈)`` with ``Y β = M q̈ + C(q, q̇) w + g`` (Slotine–Li: ``w = q̇_r``)."""
    skew_symmetric: bool
    """``Ṁ − 2C`` found skew-symmetric, exactly (:func:`~twolink_pin.symbolic.lagrange.skew_defect`)."""
    seconds: float
    """Time the derivation took [s] (when derived, not when read from the cache)."""
    from_cache: bool
    """Whether the derivation was read from the cache."""

    @property
    def n(self) -> int:
        """Number of joints."""
        return len(self.q)

    @property
    def symbol_values(self) -> dict[Any, float]:
        """Each symbol of the arm's constants (the lengths, g, β) and its value."""
        import sympy as sp

        values: dict[Any, float] = {sp.Symbol(name, real=True): value for name, value in self.lengths.items()}
        values[sp.Symbol("g", positive=True)] = self.gravity
        values.update(zip(self.beta, self.beta_values.tolist()))
        return values

    @property
    def zero_parameters(self) -> tuple[int, ...]:
        """Indices of the base parameters that are 0 in this arm (:data:`ZERO_PARAMETER`)."""
        return tuple(int(k) for k in np.flatnonzero(np.abs(self.beta_values) <= ZERO_PARAMETER))

    def shown(self, matrix: Any) -> Any:
        """``matrix`` with this arm's zero base parameters set to 0 (what is shown to people)."""
        zero = {self.beta[k]: 0 for k in self.zero_parameters}
        return matrix.xreplace(zero) if zero else matrix


def _symbols(derivation: Derivation, skeleton: Skeleton) -> tuple[dict[str, Any], dict[str, tuple[Any, ...]]]:
    """SymPy symbols for the ring's generators (by name) and the groups q, dq, ddq, w, beta."""
    import sympy as sp

    n = skeleton.n
    groups = {
        prefix: tuple(sp.Symbol(f"{prefix}{j}", real=True) for j in range(1, n + 1))
        for prefix in ("q", "dq", "ddq", "w")
    }
    groups["beta"] = tuple(
        sp.Symbol(f"beta{k}", real=True) for k in range(1, len(derivation.grouping.kept) + 1)
    )
    names: dict[str, Any] = {name: sp.Symbol(name, real=True) for name in derivation.ring.length_names}
    names["g"] = sp.Symbol("g", positive=True)
    for prefix in ("q", "dq", "ddq", "w"):
        names.update({f"{prefix}{j}": groups[prefix][j - 1] for j in range(1, n + 1)})
    return names, groups


def _definitions(derivation: Derivation, names: dict[str, Any], standard: tuple[Any, ...]) -> list[Any]:
    """Each β as ``π_k + Σ_d coefficient(lengths) π_d``."""
    import sympy as sp

    ring = derivation.ring
    gens = [names.get(name) for name in ring.names]
    out = []
    for k, combo in zip(derivation.grouping.kept, derivation.grouping.combination):
        terms = [standard[k]]
        for d, (num, den) in sorted(combo.items()):
            terms.append(sp.factor(poly_expr(num, gens) / poly_expr(den, gens)) * standard[d])
        out.append(sp.Add(*terms))
    return out


def _values(derivation: Derivation, lengths: dict[str, float], pi: np.ndarray) -> np.ndarray:
    ring = derivation.ring
    values = []
    for k, combo in zip(derivation.grouping.kept, derivation.grouping.combination):
        value = float(pi[k])
        for d, (num, den) in combo.items():
            value += ring.evaluate(num, lengths) / ring.evaluate(den, lengths) * float(pi[d])
        values.append(value)
    return np.array(values)


def equations_from(
    derivation: Derivation, skeleton: Skeleton, model: pin.Model, robot: str, from_cache: bool
) -> Equations:
    """The :class:`Equations` of ``model`` from its derivation (readable expressions, numbers)."""
    import sympy as sp

    ring, n = derivation.ring, skeleton.n
    names, groups = _symbols(derivation, skeleton)
    q, beta = groups["q"], groups["beta"]
    standard = tuple(
        sp.Symbol(f"{name}{j}", real=True) for j in range(1, n + 1) for name in BODY_PARAMETER_NAMES
    )
    lengths = skeleton.lengths()
    pi = inertial_parameters(model)

    def matrix(parts: tuple[Any, ...], rows: int, cols: int) -> Any:
        return sp.Matrix(
            rows, cols, lambda r, c: by_parameter(ring, [p[r][c] for p in parts], beta, names, q)
        )

    columns = derivation.regressor_columns()
    Y_reference = sp.Matrix(n, len(beta), lambda r, k: to_expr(ring, columns[k][r], names, q))
    same_rate = dict(zip(groups["w"], groups["dq"]))
    return Equations(
        robot=robot,
        joint_names=tuple(j.name for j in skeleton.joints),
        kinds=skeleton.kinds,
        q=q,
        dq=groups["dq"],
        ddq=groups["ddq"],
        w=groups["w"],
        beta=beta,
        beta_definitions=tuple(_definitions(derivation, names, standard)),
        beta_units=tuple(
            BODY_PARAMETER_UNITS[k % len(BODY_PARAMETER_NAMES)] for k in derivation.grouping.kept
        ),
        beta_values=readonly(_values(derivation, lengths, pi)),
        standard=standard,
        standard_names=tuple(
            f"{body_name(model, j)}.{name}" for j in range(1, model.njoints) for name in BODY_PARAMETER_NAMES
        ),
        standard_values=readonly(np.array(pi, dtype=float)),
        lengths=lengths,
        length_meanings=skeleton.length_meanings(),
        gravity=skeleton.gravity,
        M=matrix(derivation.masses, n, n),
        C=matrix(derivation.coriolis, n, n),
        g=sp.Matrix(
            n, 1, lambda r, _: by_parameter(ring, [p[r] for p in derivation.gravities], beta, names, q)
        ),
        Y=Y_reference.xreplace(same_rate),
        Y_reference=Y_reference,
        skew_symmetric=derivation.skew_symmetric,
        seconds=derivation.seconds,
        from_cache=from_cache,
    )


def derive_equations(robot: RobotModel, joints: int | None = None, use_cache: bool = True) -> Equations:
    """The equations of motion of ``robot`` (module docstring).

    Args:
        robot: The arm (:func:`~twolink_pin.model.load_robot`; its payload is in the numbers).
        joints: Derive for the first ``joints`` moving joints only, the others held at 0
            (:func:`~twolink_pin.symbolic.support.first_joints`); default all.
        use_cache: Read and keep the derivation in the cache (:mod:`~twolink_pin.symbolic.cache`).

    Raises:
        EquationsError: a joint the derivation does not handle, or too many joints.
        InvalidParameterError: ``robot`` is not a RobotModel, or ``joints`` out of range.
    """
    from twolink_pin.model import RobotModel

    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    model = robot.model if joints is None else first_joints(robot.model, joints)
    check_model(model, robot.name)
    skeleton = skeleton_of(model)
    key = skeleton.key()
    derivation = cache.load(key) if use_cache else None
    from_cache = derivation is not None
    if derivation is None:
        derivation = derive(skeleton)
        if use_cache:
            cache.store(key, derivation)
    return equations_from(derivation, skeleton, model, robot.name, from_cache)
