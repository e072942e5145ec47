"""The controller interface: a small object with a stated law.

A controller maps time, state and the reference sample to joint torques. Its internal
state (parameter estimates of an adaptive law) is an explicit vector ``z`` that the
simulator integrates beside the plant's, so a run is reproducible and resettable:
:meth:`Controller.initial_state` gives ``z(0)`` and :meth:`Controller.compute` returns
``(τ, ż)``. Stateless laws use an empty ``z``.

Notation (report): ``e = q − q_d``, ``ė = q̇ − q̇_d``, ``s = ė + λ e``,
``q̇_r = q̇_d − λ e``, ``q̈_r = q̈_d − λ ė``.
"""

from __future__ import annotations

import abc
import math
import struct
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.dynamics import Friction, polarisation_pair
from twolink_pin.errors import InvalidParameterError
from twolink_pin.model import RobotModel

EMPTY = np.zeros(0)
EMPTY.setflags(write=False)


class StageKernel(NamedTuple):
    """A law written out as Python statements on floats, for the fast RK4 loop (internal).

    :mod:`twolink_pin.simulation` inlines ``lines`` wherever the law is evaluated. Before
    they run, these floats are bound: ``q{j}``, ``v{j}`` (state, j = 0..nv−1), ``z{i}``
    (controller state), ``qd{j}``, ``vd{j}``, ``ad{j}`` (reference sample). The lines must
    bind the floats ``tau{j}`` [N·m] and ``dz{i}``, and name every temporary ``c_...``.
    Each entry of ``namespace`` (keys ``c_...``: models, Data, buffers, functions) becomes
    a local.
    The result must equal :meth:`Controller.compute` to rounding (tested).
    """

    lines: tuple[str, ...]
    """Statements, one per entry, no indentation."""
    namespace: Mapping[str, Any]
    """Objects the statements use, by name."""


def data_view(array: np.ndarray) -> memoryview:
    """A flat ``memoryview`` on a ``pin.Data`` member (``data.tau``, ``data.ddq``, ...).

    Pinocchio's Python functions return a fresh copy of their result, but the member they
    also write (e.g. ``data.tau`` for RNEA) is exposed as a live view of the Data's memory.
    Reading two floats through a memoryview costs ~60 ns, against ~300 ns for converting
    the returned array, which matters when the call itself is ~1 µs. Element ``(i, j)`` of
    a matrix member is at ``j * rows + i`` (column-major).
    """
    flat = array.T.reshape(-1) if array.ndim == 2 else array.reshape(-1)
    if not np.shares_memory(flat, array):  # pragma: no cover  # a copy would go stale
        raise AssertionError("expected a view of the Data member, got a copy")
    return memoryview(flat)  # type: ignore[arg-type]  # numpy's stubs lack __buffer__ before 3.12


def pair_namespace(model: pin.Model) -> tuple[pin.Data, dict[str, Any]]:
    """The :func:`~twolink_pin.dynamics.polarisation_pair` of ``model``, its Data and inputs.

    Returns the pair's Data and a kernel namespace with ``c_pair``, ``c_pdata`` and the input
    buffers ``c_Q``, ``c_V``, ``c_A``: consecutive slices of one buffer of ``6 nv`` floats,
    so one kernel line ``c_pack(c_in, 0, q.., q.., u⁺.., u⁻.., a..)`` (``struct.pack_into``
    on a memoryview, ~20 ns a float against ~50 ns for a numpy item assignment) writes
    ``Q = (q, q)``, ``V = (u⁺, u⁻)`` and copy A's half of ``A``; copy B's half stays zero.
    """
    pair = polarisation_pair(model)
    data = pair.createData()
    nv = model.nv
    buffer = np.zeros(6 * nv)
    view = memoryview(buffer)  # type: ignore[arg-type]  # numpy's stubs lack __buffer__ before 3.12
    namespace = {
        "c_in": view,
        "c_pack": struct.Struct(f"{5 * nv}d").pack_into,
        "c_pair": pair,
        "c_pdata": data,
        "c_Q": buffer[: 2 * nv],
        "c_V": buffer[2 * nv : 4 * nv],
        "c_A": buffer[4 * nv :],
    }
    return data, namespace


def pair_values(nv: int, a: Sequence[str]) -> str:
    """The arguments of the ``c_pack`` line of :func:`pair_namespace`: ``(q, q, u⁺, u⁻, a)``.

    ``u^± = (v ± w)/2``; expects statements binding ``c_w{j}`` (``w``) to have run.
    """
    values = (
        [f"q{j}" for j in range(nv)] * 2
        + [f"0.5 * (v{j} + c_w{j})" for j in range(nv)]
        + [f"0.5 * (v{j} - c_w{j})" for j in range(nv)]
        + [a[j] for j in range(nv)]
    )
    return ", ".join(values)


def gather(offsets: Sequence[int]) -> Callable[[memoryview], tuple[float, ...]]:
    """A function reading the float64 items at ``offsets`` (increasing) of a buffer, in one call.

    ``struct.unpack_from`` with pad bytes between the items: reading 12 regressor entries
    this way costs ~0.25 µs against ~0.5 µs item by item through a memoryview.
    """
    fmt, position = "", 0
    for offset in offsets:
        if offset < position:
            raise ValueError(f"expected increasing offsets, got {list(offsets)}")
        fmt += f"{8 * (offset - position)}xd" if offset > position else "d"
        position = offset + 1
    return struct.Struct(fmt).unpack_from


def model_term_kernel(
    model: pin.Model, nv: int, w: Sequence[str], a: Sequence[str]
) -> tuple[list[str], dict[str, Any]]:
    """Statements binding ``c_m{j}`` = ``M(q) a + C(q, v) w + g(q)`` [N·m] by one RNEA call.

    ``w`` and ``a`` are per-joint expressions (e.g. ``"vd0"``). RNEA runs once on the
    :func:`~twolink_pin.dynamics.polarisation_pair` of ``model``, which holds both terms of
    the polarisation identity; ``c_m{j} = τ_A[j] − τ_B[j]`` is read from its Data
    (:func:`data_view`).
    """
    data, namespace = pair_namespace(model)
    lines = [f"c_w{j} = {w[j]}" for j in range(nv)]
    lines.append(f"c_pack(c_in, 0, {pair_values(nv, a)})")
    lines.append("c_rnea(c_pair, c_pdata, c_Q, c_V, c_A)")
    lines += [f"c_m{j} = c_tau[{j}] - c_tau[{nv + j}]" for j in range(nv)]
    namespace.update(
        {
            "c_tau": data_view(data.tau),
            "c_rnea": pin.rnea,
        }
    )
    return lines, namespace


def literal(x: float) -> str:
    """``x`` as Python source that evaluates to exactly ``x`` (``repr`` round-trips)."""
    if not math.isfinite(x):
        raise ValueError(f"expected a finite float, got {x!r}")
    return repr(float(x))


class Controller(abc.ABC):
    """Base class: one law, one ``pin.Data`` of its own, explicit state ``z``."""

    name: ClassVar[str]
    """Registry name, e.g. ``"pd"``."""

    def __init__(self, robot: RobotModel) -> None:
        self.robot = robot
        self.model = robot.model
        self.data = robot.create_data()

    def initial_state(self) -> np.ndarray:
        """``z(0)``: the controller's internal state at the start of a run (a copy)."""
        return EMPTY

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of the estimated parameters held in ``z`` (empty if none)."""
        return ()

    def true_parameters(self) -> np.ndarray | None:
        """The estimated parameters' values on the controller's own model, or None.

        These are the values ``p̂(0)`` is scaled from. The values a run is judged against
        are the plant's: :meth:`parameters_of`.
        """
        return None

    def parameters_of(self, robot: RobotModel, friction: Friction | None) -> np.ndarray | None:
        """The estimated parameters' actual values on a plant (its arm and joint friction),
        or None if none are estimated.

        They differ from :meth:`true_parameters` when the controller was built on a model
        with parameter errors (:func:`twolink_pin.batch.robot_with_parameters`).
        """
        return None

    def stage_kernel(self) -> StageKernel | None:
        """The law as float statements for the fast simulator, or None (use :meth:`compute`).

        Subclasses that override :meth:`compute` get None unless they also provide their own
        kernel, so the fast path never runs a law other than the one ``compute`` states.
        """
        return None

    @abc.abstractmethod
    def compute(
        self,
        q: np.ndarray,
        v: np.ndarray,
        q_des: np.ndarray,
        v_des: np.ndarray,
        a_des: np.ndarray,
        z: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Torque and state derivative.

        Args:
            q: Joint positions [rad]. v: Joint velocities [rad/s].
            q_des, v_des, a_des: Reference position [rad], velocity [rad/s], acceleration [rad/s²].
            z: Controller state (see :meth:`initial_state`).

        Returns:
            ``(τ [N·m], ż)``.
        """


def diagonal_gain(
    name: str, values: Sequence[float], nv: int | None = None, positive: bool = True
) -> np.ndarray:
    """Validate a diagonal gain and return it as an array.

    Raises:
        InvalidParameterError: wrong length, non-finite, or not strictly positive.
    """
    array = np.asarray(values, dtype=float)
    if array.ndim != 1 or (nv is not None and array.shape != (nv,)):
        expected = f"shape ({nv},)" if nv is not None else "a 1-D sequence"
        raise InvalidParameterError(name, tuple(values), f"{expected} but got shape {array.shape}")
    for x in array:
        if not math.isfinite(x) or (positive and x <= 0):
            raise InvalidParameterError(name, tuple(values), "finite values > 0")
    return array


def positive_scalar(name: str, value: float, unit: str) -> float:
    """Validate a finite, strictly positive scalar."""
    if not (
        isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) and value > 0
    ):
        raise InvalidParameterError(name, value, f"a finite value > 0 {unit}")
    return float(value)
