"""Time-optimal retiming: a reference's geometric path, timed anew to be as fast as its
velocity, acceleration and effort limits allow (TOPP-RA).

**The path.** A reference keeps its geometric path: the joint path ``q(s)`` it traces, whatever
its timing. A joint via-point polynomial, a Fourier series or a sampled reference is one
path, parametrised by its own time ``s = t`` over its motion (``[t0, t0 + span]``: the rest
after it is not part of the path); an SE(3) reference is one path per segment between via
poses (its joint path ``Q_k(s)``, ``s ∈ [0, 1]``), retimed from rest to rest, because its
path turns a corner at each via pose, where any timing must stop.

**The retiming** (Pham & Pham, *A new approach to time-optimal path parameterization based
on reachability analysis*, IEEE T-RO 2018; ``toppra``): along the path, with ``x = ṡ²`` and
``u = s̈`` (``ẋ = 2u`` in ``s``), every limit is linear in ``(u, x)``::

    q̇ = q'(s) ṡ                |q̇_j| <= v_j        →  x <= (v_j / |q'_j|)²
    q̈ = q' u + q'' x           |q̈_j| <= α_j
    τ = a(s) u + b(s) x + c(s)  |τ_j| <= τ_j,  a = M q',  b = M q'' + C(q, q') q',  c = g(q)

(``a, b, c`` from three RNEA calls per grid point on the robot's model, its payload included).
TOPP-RA computes, backward from rest at the end, the set of ``x`` from which the end can be
reached at each grid point (the *controllable* sets), then goes forward from rest at the
start taking the largest admissible ``u`` that stays in them: the fastest timing the limits
allow on that grid (constraints at both ends of each interval: ``toppra``'s interpolation
discretisation). :data:`GRIDPOINTS` intervals over the whole path.

**Friction** (when asked, the plant's :class:`~twolink_pin.dynamics.Friction`): the Coulomb
torque ``C sgn(q̇) = C sgn(q')`` is known along the path (``ṡ >= 0``) and joins ``c`` (where a
joint's tangent changes sign within an interval, both bounds take the worse side); the
viscous torque ``V q' ṡ = V q' √x`` is not linear in ``x``. On the side of the limit it pushes
towards it is bounded by the tangent ``√x <= (x + x_r)/(2 √x_r)`` (conservative, exact at
``x = x_r``), on the other side dropped (conservative too); ``x_r`` is the previous pass's
``x`` (first: the velocity bound), three passes.

**Path speed cap.** Where the path's tangent vanishes (the ends of a rest-to-rest reference:
``q' = 0``) no limit bounds ``x``, and TOPP-RA's steps lose their digits; ``ṡ`` is capped at
:data:`SPEED_CAP` times the median of the velocity limits' bound along the path, and the cap is
raised if it binds where the tangent does not vanish.

**The result** is a :class:`~twolink_pin.trajectory.sampled.SampledTrajectory` with samples
at the grid points (times ``t_i = Σ 2 Δs / (ṡ_i + ṡ_{i+1})``; the acceleration jumps there,
so each interior point is sampled twice: before and after), quintic Hermite between them
(``s(t)`` is quadratic on an interval); it repeats from rest to rest with period = duration.
It is checked against every limit on the one check grid of every command
(:func:`~twolink_pin.limits.reference_motion`: each interval between two samples at evenly
spaced instants, both ends included, at most 1 ms apart; torque by RNEA); where it exceeds a
limit, the limits are tightened by that excess and the path retimed again, so that the result
is within its limits on that grid — the grid ``trajectory --time-optimal``, the report and a
``trajectory --trajectory`` of the saved file state their peaks on.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from twolink_pin import interrupts
from twolink_pin.dynamics.rigid_body import inverse_dynamics_rows
from twolink_pin.errors import InvalidParameterError, OptimizationError, require_type
from twolink_pin.limits import (
    ACCELERATION,
    EFFORT,
    VELOCITY,
    JointLimits,
    LimitsCheck,
    Motion,
    check_limits,
    check_motion,
    joint_limits,
    reference_motion,
    shortfall,
)
from twolink_pin.limits.active import ActiveLimit, active_limits
from twolink_pin.model import RobotModel
from twolink_pin.trajectory.base import Trajectory
from twolink_pin.trajectory.file_values import MAX_TIME
from twolink_pin.trajectory.retiming_path import PathPiece, path_lengths, path_pieces
from twolink_pin.trajectory.retiming_samples import (
    Timing,
    exact_motion,
    represented,
    retimed_via_times,
    timing_of,
)
from twolink_pin.trajectory.retiming_toppra import toppra_classes as _toppra
from twolink_pin.trajectory.sampled import SampledTrajectory

if TYPE_CHECKING:
    from twolink_pin.dynamics import Friction

GRIDPOINTS = 300
"""Intervals of TOPP-RA's grid over the whole path (split among an SE(3) path's segments by
their joint-space length)."""
SUBPOINTS = 4
"""Points per grid interval at which TOPP-RA's rows keep the limits (:func:`_params`): its
interpolation discretisation keeps them at both ends of an interval only, and the motion
between went 2 to 4 % beyond an effort limit on the twolink's path at 500 intervals."""
SPEED_CAP = 10.0
"""``ṡ`` at most this many times the median velocity-limit bound along the path (see the
module docstring)."""
CLUSTER = 0.95
"""How much denser the grid is at a path's ends: spacing ``1 − CLUSTER`` times the mean there."""
FRICTION_PASSES = 3
"""Passes of the viscous-friction tangent bound (module docstring)."""
TIGHTENING_ROUNDS = 4
"""Most retimings with the limits tightened by what the check grid finds beyond them."""
MARGIN = 3e-3
"""The timing keeps this fraction of each limit free: for what happens between TOPP-RA's
grid points (it keeps the limits at :data:`SUBPOINTS` + 1 points of each interval) and for
the samples' interpolation, so that the check (the check grid, at most 1 ms apart on each
sample interval) passes at the first try (the twolink's path went 0.18 % beyond near its end with 0.1 % free:
a second retiming, tightened by twice that, cost more time and more duration); where it does
not, the limits are tightened by twice what it found."""
REPRESENTATION = 1e-5
"""Acceleration error sought of the samples' interpolation, a fraction of the path's largest
acceleration (an interval is halved, at most :data:`MAX_LEVEL` times, until it is met)."""


class TimeOptimal(NamedTuple):
    """What :func:`time_optimal` returns."""

    trajectory: SampledTrajectory
    """The retimed reference (rest to rest, period = duration)."""
    duration: float
    """Its duration [s]."""
    original_duration: float
    """The reference's motion it retimed: its span (a polynomial's, an SE(3) reference's
    via-point span) or period [s]."""
    limits: JointLimits
    """The limits it was retimed within (scaled)."""
    check: LimitsCheck
    """Every limit on the check grid (:func:`~twolink_pin.limits.reference_motion`)."""
    active: tuple[ActiveLimit, ...]
    """Where each limit is active (within 1 %)."""
    gridpoints: int
    """TOPP-RA's grid intervals."""
    seconds: float
    """Wall time of the retiming [s]."""


class _Stage(NamedTuple):
    """A piece's path on its grid, :data:`SUBPOINTS` points per interval, and the
    coefficients of its torque there."""

    s: np.ndarray
    """Points [path parameter], shape (N K + 1,): the grid is ``s[::K]``."""
    q: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    """``q, q', q''`` at the points, each (N K + 1, nv)."""
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    """The torque's ``a, b, c`` at the points (friction's Coulomb part in ``c``)."""

    @property
    def grid(self) -> np.ndarray:
        """TOPP-RA's grid points, shape (N + 1,)."""
        return self.s[::SUBPOINTS]


def _stage(robot: RobotModel, piece: PathPiece, grid: np.ndarray, friction: Friction | None) -> _Stage:
    """Sample ``piece`` at :data:`SUBPOINTS` points per interval of ``grid`` and compute its
    torque coefficients there."""
    theta = np.arange(SUBPOINTS) / SUBPOINTS
    s = np.append((grid[:-1, None] + np.diff(grid)[:, None] * theta).ravel(), grid[-1])
    q, dq, ddq = (piece.path(s, r) for r in range(3))
    zero = np.zeros_like(dq)
    c = inverse_dynamics_rows(robot.model, q, zero, zero)
    a = inverse_dynamics_rows(robot.model, q, zero, dq) - c
    b = inverse_dynamics_rows(robot.model, q, dq, ddq) - c
    return _Stage(s, q, dq, ddq, a, b, c)


def _coulomb_signs(stage: _Stage) -> tuple[np.ndarray, np.ndarray]:
    """The sign of the Coulomb torque ``C sgn(q̇) = C sgn(q')`` at each point, as the upper and
    the lower bound of the torque see it: where a joint's tangent changes sign (or vanishes)
    within an interval, the flip can fall anywhere between its points, so both bounds take
    the worse side there (+1 for the upper, −1 for the lower)."""
    sign = np.sign(stage.dq)
    K = SUBPOINTS
    n = (stage.s.size - 1) // K
    blocks = np.concatenate([sign[:-1].reshape(n, K, -1), sign[K::K][:, None, :]], axis=1)  # (n, K + 1, nv)
    mixed = (blocks.min(axis=1) != blocks.max(axis=1)) | (blocks == 0).any(axis=1)  # (n, nv)
    point_mixed = np.zeros_like(sign, dtype=bool)
    point_mixed[:-1] = np.repeat(mixed, K, axis=0)
    point_mixed[K::K] |= mixed  # an interval's end point belongs to its rows too
    return np.where(point_mixed, 1.0, sign), np.where(point_mixed, -1.0, sign)


def _speed_bound(stage: _Stage, limits: JointLimits) -> np.ndarray:
    """``(v_j / |q'_j|)²`` minimised over the joints at each point (``inf`` where the tangent vanishes)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(np.abs(stage.dq) > 0, limits.velocity / np.abs(stage.dq), np.inf)
    return np.min(ratio, axis=1) ** 2


def _params(
    stage: _Stage, limits: JointLimits, cap: float, friction: Friction | None, x_ref: np.ndarray | None
) -> Callable[[np.ndarray], tuple[np.ndarray, ...]]:
    """The rows of :class:`Limits` for ``stage``: at grid point ``i``, the limits at each point
    ``s_i + θ Δ`` of its interval (θ = 0, 1/K, .., 1), where ``x = x_i + 2 θ Δ u`` (TOPP-RA's
    constant ``u`` on the interval), so a row ``a u + b x + c`` there is
    ``(a + 2 θ Δ b) u + b x_i + c``; the velocity too, ``x <= (v_j/|q'_j|)²``, divided by its
    bound. The last grid point has its own rows only."""

    def params(grid: np.ndarray) -> tuple[np.ndarray, ...]:
        K, n = SUBPOINTS, grid.size - 1
        eff, acc = limits.given(EFFORT), np.isfinite(limits.acceleration)
        a, b, c = stage.a[:, eff], stage.b[:, eff], stage.c[:, eff]
        up_b, up_c, lo_b, lo_c = b.copy(), c.copy(), b.copy(), c.copy()
        if friction is not None:
            up, lo = _coulomb_signs(stage)
            coulomb = np.asarray(friction.coulomb)[eff]
            up_c, lo_c = up_c + coulomb * up[:, eff], lo_c + coulomb * lo[:, eff]
        if friction is not None and x_ref is not None:
            xr = np.maximum(np.interp(stage.s, grid, x_ref), 1e-12)[:, None]
            slope = np.asarray(friction.viscous)[eff] * stage.dq[:, eff]
            beta, gamma = slope / (2.0 * np.sqrt(xr)), 0.5 * slope * np.sqrt(xr)
            up_b, up_c = up_b + np.where(slope > 0, beta, 0.0), up_c + np.where(slope > 0, gamma, 0.0)
            lo_b, lo_c = lo_b + np.where(slope < 0, beta, 0.0), lo_c + np.where(slope < 0, gamma, 0.0)
        bound = np.minimum(_speed_bound(stage, limits), cap)
        weight = 1.0 / bound
        A = np.concatenate([a, a, stage.dq[:, acc], np.zeros((stage.s.size, 1))], axis=1)
        B = np.concatenate([up_b, lo_b, stage.ddq[:, acc], weight[:, None]], axis=1)
        C = np.concatenate([up_c, lo_c, np.zeros((stage.s.size, int(acc.sum()) + 1))], axis=1)
        # rows of grid point i: its interval's points j = 0..K (θ = j/K); the last: its own point
        index = np.minimum(np.arange(n + 1)[:, None] * K + np.arange(K + 1)[None, :], stage.s.size - 1)
        theta = np.where(np.arange(n + 1)[:, None] < n, np.arange(K + 1)[None, :] / K, 0.0)
        delta = np.append(np.diff(grid), 0.0)[:, None, None]
        A_rows = A[index] + 2.0 * (theta[:, :, None] * delta) * B[index]
        rows = A_rows.shape[2]
        k, m = int(eff.sum()), int(acc.sum())
        F1 = np.zeros((2 * k + 2 * m + 1, rows))
        F1[:k, :k], F1[k : 2 * k, k : 2 * k] = np.eye(k), -np.eye(k)
        F1[2 * k : 2 * k + m, 2 * k : 2 * k + m], F1[2 * k + m : 2 * k + 2 * m, 2 * k : 2 * k + m] = (
            np.eye(m),
            -np.eye(m),
        )
        F1[-1, -1] = 1.0
        g1 = np.concatenate(
            [
                limits.effort[eff],
                limits.effort[eff],
                limits.acceleration[acc],
                limits.acceleration[acc],
                [1.0],
            ]
        )
        F = np.kron(np.eye(K + 1), F1)
        g = np.tile(g1, K + 1)
        xbound = np.stack([np.zeros(n + 1), bound[::K]], axis=1)
        return (
            A_rows.reshape(n + 1, -1),
            B[index].reshape(n + 1, -1),
            C[index].reshape(n + 1, -1),
            F,
            g,
            xbound,
        )

    return params


def _check_rest(robot: RobotModel, stage: _Stage, limits: JointLimits, where: str) -> None:
    """Raise (bad input) where the path needs more than an effort limit to hold still: at its
    rest points (the torque there is gravity, and nothing can lower it), then anywhere along it
    (``c(s)``: gravity, which the timing cannot lower either)."""
    points = [(0, f"at rest at the start of {where}"), (-1, f"at rest at the end of {where}")]
    points += [(int(i), f"to hold still on {where}") for i in np.argsort(-np.abs(stage.c).max(axis=1))[:1]]
    for index, label in points:
        excess = np.abs(stage.c[index]) - limits.effort
        j = int(np.argmax(excess))
        if excess[j] > 0:
            raise InvalidParameterError(
                f"effort limit of joint {j + 1} ({limits.joint_names[j]})",
                f"{limits.effort[j]:g} N·m",
                f"at least the {abs(stage.c[index][j]):.4g} N·m that gravity needs {label} "
                f"(q = {np.round(stage.q[index], 4).tolist()} rad): the path needs more torque than the limits allow "
                "even at rest",
            )


def _check_needs(robot: RobotModel, trajectory: Trajectory, limits: JointLimits, span: float) -> None:
    """Raise (bad input) for a velocity, acceleration or effort limit so far below what the
    reference needs at its own timing (over ``span`` [s]) that no retiming shorter than
    :data:`~twolink_pin.trajectory.file_values.MAX_TIME` keeps it: slowed ``k`` times, a path
    needs ``1/k`` of its velocity and ``1/k²`` of its acceleration and dynamic torque (the
    gravity, which it does not lower, is :func:`_check_rest`'s). A limit scale of 1e-300 gave
    numpy's warnings and "TOPP-RA found no admissible timing"."""
    factor = MAX_TIME / max(span, 1e-300)
    short = shortfall(
        check_limits(robot, trajectory, limits=limits), lambda kind: factor if kind is VELOCITY else factor**2
    )
    if short is not None:
        what, value, need = short.describe(limits.joint_names)
        raise InvalidParameterError(
            what, value, f"a limit a retiming shorter than {MAX_TIME:g} s can keep: it is {need}"
        )


def _solve(
    robot: RobotModel, stage: _Stage, limits: JointLimits, friction: Friction | None, what: str
) -> np.ndarray:
    """``ṡ`` on the stage's grid from rest to rest (TOPP-RA; module docstring)."""
    lib = _toppra()
    bound = _speed_bound(stage, limits)
    grid = stage.grid
    tangent = (np.abs(stage.dq).max(axis=1) > 1e-3 * np.abs(stage.dq).max())[::SUBPOINTS]
    cap_factor, x_ref = SPEED_CAP, None
    for _ in range(8):
        cap = (cap_factor * float(np.sqrt(np.median(bound[np.isfinite(bound)])))) ** 2
        if friction is not None and x_ref is None:
            x_ref = np.minimum(bound[::SUBPOINTS], cap)
        sd = None
        for _ in range(FRICTION_PASSES if friction is not None else 1):
            interrupts.check()
            constraint = lib.Limits(_params(stage, limits, cap, friction, x_ref), robot.nv)
            path = lib.Path(PathPiece(lambda s, r: s, grid[0], grid[-1]), robot.nv)
            algorithm = lib.toppra.algorithm.TOPPRA(
                [constraint], path, gridpoints=grid, solver_wrapper="seidel"
            )
            _, sd, _ = algorithm.compute_parameterization(0.0, 0.0)
            if sd is None or not np.all(np.isfinite(sd)):
                raise OptimizationError(
                    what,
                    "TOPP-RA found no admissible timing (the path is not controllable within the limits)",
                    1,
                )
            x_ref = np.maximum(sd**2, 1e-9 * cap)
        assert sd is not None
        if not np.any(tangent & (sd**2 >= 0.999 * cap)):
            return np.asarray(sd, dtype=float)
        cap_factor *= 4.0
    raise OptimizationError(what, "the path speed cap still binds after raising it 8 times", 8)


def _torque(
    robot: RobotModel, q: np.ndarray, v: np.ndarray, a: np.ndarray, friction: Friction | None
) -> np.ndarray:
    """``RNEA(q, q̇, q̈) (+ f(q̇))`` at each row [N·m]."""
    tau = inverse_dynamics_rows(robot.model, q, v, a)
    return tau if friction is None else tau + friction.torque(v)


def verify_motion(
    robot: RobotModel, trajectory: SampledTrajectory, per_interval: int, friction: Friction | None = None
) -> Motion:
    """``trajectory`` on :meth:`~twolink_pin.trajectory.sampled.SampledTrajectory.dense`'s grid
    with the torque it needs there (RNEA on the robot's model, plus ``friction``)."""
    t, sample = trajectory.dense(per_interval)
    return Motion(t, sample.q, sample.v, sample.a, _torque(robot, sample.q, sample.v, sample.a, friction))


def _over(motion: Motion, limits: JointLimits) -> float:
    """The largest excess of a velocity, acceleration or effort limit along ``motion`` (a
    fraction of it; negative: within every one)."""
    worst = -np.inf
    for kind in (VELOCITY, ACCELERATION, EFFORT):
        values = kind.of(motion)
        given = limits.given(kind)
        if values is None or not given.any():
            continue
        _, upper = limits.bounds(kind)
        worst = max(worst, float(np.max(limits.excess(kind, values)[:, given] / upper[given])))
    return worst


def _timed(
    robot: RobotModel,
    trajectory: Trajectory,
    pieces: list[PathPiece],
    stages: list[_Stage],
    limits: JointLimits,
    friction: Friction | None,
) -> tuple[SampledTrajectory, list[Timing]]:
    """Each piece timed within ``limits`` (TOPP-RA), one after the other, and the samples of
    the whole: what :func:`time_optimal` checks."""
    timings: list[Timing] = []
    for piece, stage in zip(pieces, stages, strict=True):
        sd = _solve(robot, stage, limits, friction, "the time-optimal retiming")
        timings.append(timing_of(piece, stage.grid, sd, 0.0 if not timings else float(timings[-1].t[-1])))
    scale = max(
        max(
            float(np.abs(exact_motion(tm, np.arange(tm.u.size), np.zeros(tm.u.size))[3]).max())
            for tm in timings
        ),
        1e-9,
    )
    t, q, v, a = represented(timings, REPRESENTATION * scale)
    same = np.flatnonzero(np.diff(t) == 0)
    q[same + 1], v[same + 1] = q[same], v[same]  # a junction of two pieces: one configuration
    q[-1], v[-1] = q[0], v[0]  # the path closes (to its IK's digits for an SE(3) reference)
    tau = _torque(robot, q, v, a, friction)
    return SampledTrajectory(t, q, v, a, tau, retimed_via_times(trajectory, timings)), timings


def time_optimal(
    robot: RobotModel,
    trajectory: Trajectory,
    *,
    limit_scale: float = 1.0,
    limits: JointLimits | None = None,
    friction: Friction | None = None,
    gridpoints: int = GRIDPOINTS,
) -> TimeOptimal:
    """The shortest timing of ``trajectory``'s geometric path within the robot's velocity,
    acceleration and effort limits (TOPP-RA; module docstring), from rest to rest.

    Args:
        robot: The arm (its model, payload included, gives the torque).
        trajectory: The reference whose path is kept.
        limit_scale: Fraction ``0 < F <= 1`` of each velocity, acceleration and effort
            limit to use (headroom for feedback).
        limits: The limits (default :func:`~twolink_pin.limits.joint_limits` of ``robot``).
        friction: A plant's joint friction added to the torque, or None.
        gridpoints: Intervals of TOPP-RA's grid.

    Raises:
        InvalidParameterError: a joint without a velocity limit, ``limit_scale`` outside
            (0, 1], or a path that needs more torque than the limits allow even at rest.
        OptimizationError: TOPP-RA found no timing, or the result stays beyond a limit.
    """
    require_type(robot, RobotModel, "robot", "a RobotModel (twolink_pin.load_robot)")
    require_type(trajectory, Trajectory, "trajectory", "a Trajectory (twolink_pin.default_trajectory)")
    if not (isinstance(gridpoints, int) and not isinstance(gridpoints, bool) and 20 <= gridpoints <= 100_000):
        raise InvalidParameterError("gridpoints", gridpoints, "an integer from 20 to 100000")
    base = joint_limits(robot) if limits is None else limits
    base.require(VELOCITY, "retime a path to its shortest duration")
    _toppra()  # imported once (about 1 s), before the clock starts
    start = time.perf_counter()
    wanted = base.scaled(limit_scale)
    _check_needs(robot, trajectory, wanted, float(getattr(trajectory, "span", trajectory.period)))
    pieces = path_pieces(trajectory)
    lengths = path_lengths(pieces)
    if not np.all(lengths > 0):
        k = int(np.flatnonzero(lengths <= 0)[0])
        raise InvalidParameterError("trajectory", f"segment {k} does not move", "a path that moves to retime")
    counts = np.maximum(50, np.round(gridpoints * lengths / lengths.sum())).astype(int)
    grids = [
        p.start + (p.end - p.start) * np.linspace(0.0, 1.0, int(n) + 1)
        for p, n in zip(pieces, counts, strict=True)
    ]
    stages = [_stage(robot, p, g, friction) for p, g in zip(pieces, grids, strict=True)]
    for k, stage in enumerate(stages):
        _check_rest(
            robot, stage, wanted, "the path" if len(stages) == 1 else f"segment {k} (via pose {k} → {k + 1})"
        )
    working, excess = wanted.scaled(1.0 - MARGIN), np.inf
    for _ in range(TIGHTENING_ROUNDS):
        result, _ = _timed(robot, trajectory, pieces, stages, working, friction)
        motion = reference_motion(robot, result, friction=friction)  # the one check grid
        excess = _over(motion, wanted)
        if excess <= 0:
            original = float(getattr(trajectory, "span", trajectory.period))
            return TimeOptimal(
                result, result.period, original, wanted, check_motion(motion, wanted),
                active_limits(motion, wanted), int(sum(st.grid.size - 1 for st in stages)),
                time.perf_counter() - start,
            )  # fmt: skip
        working = working.scaled(1.0 / (1.0 + 2.0 * excess + MARGIN))
    raise OptimizationError(
        "the time-optimal retiming",
        f"the retimed path still exceeds a limit by {excess:.3g} of it on the check grid",
        TIGHTENING_ROUNDS,
    )


__all__ = ["GRIDPOINTS", "TimeOptimal", "path_pieces", "time_optimal", "verify_motion"]
