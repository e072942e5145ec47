"""The step checked before a run: the fastest mode of its start against the integrator's bound.

A fixed-step integrator is stable on a linear system ``ẋ = A x`` only where every ``λ dt`` of
``A`` lies in its stability region. This module linearises the closed loop at the run's start
and checks that, before anything runs:

* **the law**, at ``t = 0``, the run's initial state ``(q(0), q̇(0), z(0))`` and the reference's
  first sample: ``∂τ/∂(q, q̇, z)`` and ``∂ż/∂(q, q̇, z)`` by central differences of the law's
  own :meth:`~twolink_pin.controllers.Controller.compute`, all perturbations evaluated as one
  batch of runs on a copy of the law (its counters and warnings untouched). That needs no
  knowledge of the law's gains, so it holds for a user's law as for the built-in ones; a law
  that plans (``update_period``) first makes the plan the engine would make at ``t = 0``;
* **the plant**: ``M(q(0))`` of its model plus the armature of its
  :meth:`~twolink_pin.plant.Plant.linear_terms`, the rigid bodies' ``∂τ/∂q`` and ``∂τ/∂q̇``
  (Pinocchio's ``computeRNEADerivatives`` at the start's acceleration) and the plant's joint
  damping and stiffness from the same :class:`~twolink_pin.plant.LinearTerms`.

The bound of each integrator (``z = λ dt``):

* ``rk4``, the law at every stage: ``|R(z)| ≤ 1`` with ``R(z) = 1 + z + z²/2 + z³/6 + z⁴/24`` —
  on the real axis to ``λ dt = −2.785`` (:data:`RK4_REAL_AXIS`), on the imaginary axis to
  ``±2.828 i`` (``2√2``, :data:`RK4_IMAGINARY_AXIS`), and between them along each ray
  (:func:`rk4_radius`). Every mode of the start that is stable (``Re λ ≤ 0``) must lie inside;
  a mode that grows in the continuous closed loop itself is the law's, not the step's, and is
  not refused here;
* ``rk4`` with a sampled law (``control_period`` = m steps, or a delay): the law is held over
  each period and ``z`` moves by Euler (:mod:`twolink_pin.simulation.engine`): the check takes
  the exact one-period map of the linearisation (m RK4 steps of the plant under the held
  torque, ``z ← z + T ż``) and asks its spectral radius to be at most 1 (or at most the
  continuous loop's own growth over the period). A delay's extra lag is not modelled;
* ``adaptive`` (DOP853): no bound — its step adapts to a stiff start (at the cost of
  evaluations), so nothing is checked.

The MuJoCo plant (``--plant mujoco``) with its default integrator is advanced by the same RK4,
the law at every stage: its start is checked as the Pinocchio plant's (the same ``M(q)`` with the
armature, the same joint damping; MuJoCo's dry friction is not linear and its soft limits act
only at a limit). With ``--mujoco-integrator euler`` or ``implicitfast`` MuJoCo steps the run
itself, the law held over each step and the damping implicit: those stability regions are
MuJoCo's, not modelled here, and such runs are not checked (a divergence is reported with
MuJoCo's cause).

Beyond the bound the run is refused (:class:`~twolink_pin.errors.StepTooLargeError`, exit 2)
with the rate, the joint the mode moves most, what sets it (the plant's joint damping, or the
law's gain whose rate on the arm's inertia matches it) and the largest stable step. The check
costs one batched law evaluation of ``2 (2 nv + nz)`` runs and one eigenvalue problem: a few
milliseconds (``scripts/benchmark.py``).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import warnings
from functools import cache
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from twolink_pin.controllers import Controller
from twolink_pin.controllers.gains import gain_spec
from twolink_pin.errors import ControllerError, StepTooLargeError
from twolink_pin.plant import Plant
from twolink_pin.simulation.config import SimulationConfig, initial_state
from twolink_pin.simulation.containment import contained
from twolink_pin.simulation.deadline import bounded, timed_out
from twolink_pin.simulation.task_reference import law_input
from twolink_pin.simulation.terms import terms_for
from twolink_pin.trajectory import Trajectory

RK4_REAL_AXIS = 2.785293563405282
"""``|λ| dt`` at which RK4 stops being stable on the negative real axis."""
RK4_IMAGINARY_AXIS = 2.0 * math.sqrt(2.0)
"""``|λ| dt`` at which RK4 stops being stable on the imaginary axis (``2√2``)."""
GROWTH_TOLERANCE = 1e-9
"""An amplification ``|R(λ dt)|`` up to ``1 + this`` per step counts as stable."""
RELATIVE_STEP = 1e-6
"""Central differences of the law: the step on a coordinate is this × max(1, |value|)."""


def rk4_amplification(z: np.ndarray) -> np.ndarray:
    """``|R(z)|``, RK4's amplification of a mode with ``z = λ dt`` over one step."""
    z = np.asarray(z, dtype=complex)
    return np.abs(1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0))))


@cache
def _radius_table() -> tuple[np.ndarray, np.ndarray]:
    """RK4's stability radius along rays of angle θ ∈ [π/2, π] (181 rays): the first r > 0
    with ``|R(r e^{iθ})| > 1`` (a fine scan, then bisection)."""
    angles = np.linspace(0.5 * np.pi, np.pi, 181)
    r = np.linspace(1e-3, 3.0, 3000)
    radii = np.empty_like(angles)
    for i, theta in enumerate(angles):
        outside = rk4_amplification(r * np.exp(1j * theta)) > 1.0 + GROWTH_TOLERANCE
        low, high = (r[np.argmax(outside) - 1], r[np.argmax(outside)]) if outside.any() else (3.0, 3.0)
        for _ in range(40):
            mid = 0.5 * (low + high)
            if rk4_amplification(mid * np.exp(1j * theta)) > 1.0 + GROWTH_TOLERANCE:
                high = mid
            else:
                low = mid
        radii[i] = low
    return angles, radii


def rk4_radius(eigenvalue: complex) -> float:
    """``|λ| dt`` at which RK4 stops being stable for a mode ``λ`` with ``Re λ ≤ 0`` (2.785 on
    the real axis, 2.828 on the imaginary one; interpolated between 181 rays)."""
    angles, radii = _radius_table()
    theta = float(np.clip(abs(np.angle(complex(eigenvalue))), 0.5 * np.pi, np.pi))
    return float(np.interp(theta, angles, radii))


class Linearisation(NamedTuple):
    """The closed loop linearised at a run's start (state ``x = (q, q̇, z)``)."""

    A: np.ndarray
    """``∂ẋ/∂x`` [1/s …], shape (2 nv + nz, 2 nv + nz)."""
    plant: np.ndarray
    """The plant alone, ``[[0, I], [−M⁻¹ ∂τ/∂q, −M⁻¹ (∂τ/∂q̇ + D)]]``, (2 nv, 2 nv)."""
    B: np.ndarray
    """The torque's input ``[0; M⁻¹]``, (2 nv, nv)."""
    law: np.ndarray
    """``∂(τ, ż)/∂x`` of the law, (nv + nz, 2 nv + nz)."""
    inertia: np.ndarray
    """``M(q(0))`` plus the plant's armature [kg·m²], (nv, nv)."""
    damping: np.ndarray
    """The plant's joint damping [N·m·s/rad], (nv,)."""


class StepCheck(NamedTuple):
    """What :func:`check_step` found for one run."""

    stable: bool
    """Whether the integrator is stable on every mode of the start (True for ``adaptive``)."""
    method: str
    """The integrator checked (``rk4``, ``rk4, control period 0.01 s``, ``adaptive``)."""
    step: float
    """The step checked [s]: ``dt``, or the control period of a sampled law."""
    largest_step: float
    """The largest stable step [s] (``inf`` for ``adaptive``)."""
    eigenvalue: complex
    """The start's mode that bounds the step [1/s] (its rate is ``|λ|``)."""
    joint: int | None
    """The joint that mode moves most (0-based), None for a mode of the law's state alone."""
    cause: str
    """What sets that mode, in words."""

    @property
    def rate(self) -> float:
        """``|λ|`` of the bounding mode [1/s]."""
        return abs(self.eigenvalue)


def initial_law_input(
    controller: Controller, plant: Plant, trajectory: Trajectory, config: SimulationConfig
) -> Any:
    """The law's input at the run's start (:func:`~twolink_pin.simulation.config.initial_state`,
    one run, the law's ``z(0)``) with the reference's first sample."""
    q0, v0 = initial_state(plant, trajectory, config)
    ref = trajectory.sample(np.array([0.0]))
    z0 = np.atleast_2d(np.asarray(controller.initial_state(), dtype=float))[:1]
    q_des, v_des, a_des = (np.ascontiguousarray(np.atleast_2d(x)) for x in (ref.q, ref.v, ref.a))
    return law_input(controller, 0.0, q0[None], v0[None], z0, q_des, v_des, a_des, trajectory=trajectory)


def _copy(controller: Controller) -> Controller:
    """A copy of the law that shares its robot (its counters, warnings and plan untouched)."""
    return copy.deepcopy(controller, {id(controller.robot): controller.robot})


def _evaluate(law: Controller, x: Any, rows: np.ndarray) -> np.ndarray:
    """``(τ, ż)`` of the law at the states ``rows`` = (q, q̇, z) (N, 2 nv + nz), one batch:
    (N, nv + nz)."""
    n, nv, nz = rows.shape[0], x.q.shape[1], x.z.shape[1]
    q, v, z = (np.ascontiguousarray(rows[:, a:b]) for a, b in ((0, nv), (nv, 2 * nv), (2 * nv, 2 * nv + nz)))
    out = contained(law)(x._replace(q=q, v=v, z=z), terms_for(law, n, threads=1))
    tau = np.broadcast_to(np.asarray(out[0], dtype=float), (n, nv))
    dz = np.zeros((n, nz)) if out[1] is None else np.broadcast_to(np.asarray(out[1], dtype=float), (n, nz))
    return np.concatenate([tau, dz], axis=1)


SMOOTHNESS = 0.1
"""A derivative whose central differences at steps h and 2h differ by more than this fraction
is taken for a jump (an exact ``sgn q̇`` at q̇ = 0): a bounded term, not a rate, left out."""


def _law_jacobian(law: Controller, x: Any) -> tuple[np.ndarray, np.ndarray]:
    """``∂(τ, ż)/∂(q, q̇, z)`` at ``x`` (central differences at h and 2h on q and q̇, Richardson's
    combination where they agree, 0 where they do not; forward differences on z), and
    ``(τ, ż)`` at ``x``: all ``8 nv + nz + 1`` states in one batch."""
    state = np.concatenate([x.q[0], x.v[0], x.z[0]])
    n, m = state.size, 2 * x.q.shape[1]
    h = RELATIVE_STEP * np.maximum(1.0, np.abs(state))
    moves = [np.zeros(n)]  # the base state first
    for j in range(m):
        moves += [h[j] * e for e in (np.eye(n)[j], -np.eye(n)[j], 2 * np.eye(n)[j], -2 * np.eye(n)[j])]
    moves += [h[j] * np.eye(n)[j] for j in range(m, n)]
    values = _evaluate(law, x, state + np.array(moves))
    base, rest = values[0], values[1:]
    near = rest[: 4 * m : 4] - rest[1 : 4 * m : 4]
    far = rest[2 : 4 * m : 4] - rest[3 : 4 * m : 4]
    d1, d2 = near / (2 * h[:m, None]), far / (4 * h[:m, None])
    floor = 1e-9 * max(float(np.abs(d1).max(initial=0.0)), 1e-300)
    jump = np.abs(d1 - d2) > SMOOTHNESS * np.abs(d1) + floor
    columns = np.where(jump, 0.0, (4 * d1 - d2) / 3)
    forward = (rest[4 * m :] - base) / h[m:, None]
    return np.vstack([columns, forward]).T, base


def linearise(controller: Controller, plant: Plant, x: Any) -> Linearisation:
    """The closed loop of ``controller`` on ``plant`` linearised at the law input ``x`` (one run)."""
    law = _copy(controller)
    if law.update_period() is not None:  # the plan the engine makes at t = 0
        x = x._replace(z=np.asarray(contained(law, "update")(x, terms_for(law, 1)), dtype=float))
    nv, nz = x.q.shape[1], x.z.shape[1]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        jacobian, base = _law_jacobian(law, x)
    tau0 = base[:nv]
    model, data = plant.model, plant.model.createData()
    terms = plant.linear_terms()
    q0, v0 = x.q[0], x.v[0]
    a0 = pin.aba(model, data, q0, v0, plant.motor_torque(v0, tau0))
    pin.computeRNEADerivatives(model, data, q0, v0, a0)
    dq, dv = np.array(data.dtau_dq), np.array(data.dtau_dv)
    M = pin.crba(model, data, q0)
    M = np.triu(M) + np.triu(M, 1).T + np.diag(terms.armature)
    Minv = np.linalg.inv(M)
    stiffness, damping = dq + np.diag(terms.stiffness), dv + np.diag(terms.damping)
    open_loop = np.block([[np.zeros((nv, nv)), np.eye(nv)], [-Minv @ stiffness, -Minv @ damping]])
    B = np.vstack([np.zeros((nv, nv)), Minv])
    n = 2 * nv + nz
    A = np.zeros((n, n))
    A[: 2 * nv, : 2 * nv] = open_loop
    A[: 2 * nv] += B @ jacobian[:nv]
    A[2 * nv :] = jacobian[nv:]
    return Linearisation(A, open_loop, B, jacobian, M, np.array(terms.damping, dtype=float))


def _rk4_step_map(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One RK4 step of ``ẋ = A x + B u`` with ``u`` held: ``x⁺ = R x + S u``."""
    Z = A * dt
    eye = np.eye(A.shape[0])
    Z2 = Z @ Z
    R = eye + Z + Z2 / 2 + Z2 @ Z / 6 + Z2 @ Z2 / 24
    S = (eye + Z / 2 + Z2 / 6 + Z2 @ Z / 24) @ B * dt
    return R, S


def sampled_radius(lin: Linearisation, dt: float, steps: int) -> float:
    """Spectral radius of one period (``steps`` RK4 steps of ``dt`` [s], the law held, ``z`` by
    Euler) of the linearised sampled loop."""
    nv2 = lin.plant.shape[0]
    nz = lin.A.shape[0] - nv2
    nv = nv2 // 2
    R, S = _rk4_step_map(lin.plant, lin.B, dt)
    Phi, Gamma = np.eye(nv2), np.zeros((nv2, nv))
    for _ in range(steps):
        Phi, Gamma = R @ Phi, R @ Gamma + S
    period = dt * steps
    tau, dz = lin.law[:nv], lin.law[nv:]
    top = np.hstack([Phi, np.zeros((nv2, nz))]) + Gamma @ tau
    bottom = np.hstack([np.zeros((nz, nv2)), np.eye(nz)]) + period * dz
    return float(np.max(np.abs(np.linalg.eigvals(np.vstack([top, bottom])))))


def _sampled_stable(radius: float, eigenvalues: np.ndarray, period: float) -> bool:
    """Whether a sampled loop whose one-period map has spectral radius ``radius`` is stable as far
    as the step goes: radius ≤ 1 when the continuous loop is stable; when the continuous loop
    itself grows at σ > 0 at the start (the law's doing, e.g. an adaptive law's friction
    estimates at rest), the held law may add up to :data:`SAMPLED_SLACK` per period to ``e^{σT}``."""
    sigma = max(0.0, float(np.max(eigenvalues.real))) if eigenvalues.size else 0.0
    if sigma <= 1e-9:
        return radius <= 1.0 + GROWTH_TOLERANCE
    return radius <= math.exp(sigma * period) * (1.0 + SAMPLED_SLACK)


SAMPLED_SLACK = 0.1
"""A sampled loop whose continuous start already grows is refused only when the held law makes
it grow 10 % more per period: a step that is too long does far more."""


def _largest_stage_step(eigenvalues: np.ndarray) -> tuple[float, complex]:
    """The largest RK4 step [s] stable on every mode with ``Re λ ≤ 0``, and the mode that bounds it."""
    best, bound = math.inf, 0j
    for lam in eigenvalues:
        if lam.real > 1e-9 * abs(lam) or abs(lam) == 0:
            continue
        step = rk4_radius(lam) / abs(lam)
        if step < best:
            best, bound = step, complex(lam)
    return best, bound


def _largest_period(lin: Linearisation, eigenvalues: np.ndarray, dt: float, steps: int) -> float:
    """The largest stable control period [s] (a multiple of ``dt``, at most ``steps`` of them)."""
    low, high = 0, steps
    while high - low > 1:
        mid = (low + high) // 2
        if _sampled_stable(sampled_radius(lin, dt, mid), eigenvalues, dt * mid):
            low = mid
        else:
            high = mid
    return low * dt


def _joint_of(lin: Linearisation, eigenvalue: complex) -> int | None:
    """The joint whose velocity the mode ``eigenvalue`` moves most (None: the law's state alone)."""
    values, vectors = np.linalg.eig(lin.A)
    w = vectors[:, int(np.argmin(np.abs(values - eigenvalue)))]
    nv = lin.inertia.shape[0]
    motion = np.abs(w[:nv]) * max(abs(eigenvalue), 1.0) + np.abs(w[nv : 2 * nv])
    if motion.max() < 1e-9 * np.abs(w).max():
        return None
    return int(np.argmax(motion))


def _gain_rates(controller: Controller, inertia: np.ndarray) -> dict[str, float]:
    """Each gain's own rate on the arm [1/s], by its unit: a damping-like gain (N·m·s/rad) the
    largest generalised eigenvalue of (K, M), a stiffness (N·m/rad) its square root, an integral
    gain (N·m/(rad·s)) its cube root, a rate (1/s) itself, an acceleration gain (1/s²) its root."""
    rates: dict[str, float] = {}
    nv = inertia.shape[0]
    minv = np.linalg.inv(inertia)
    for f in dataclasses.fields(controller.gains):
        value, unit = getattr(controller.gains, f.name), gain_spec(f).unit
        if value is None or isinstance(value, (bool, str)):
            continue
        array = np.asarray(value, dtype=float)
        power = {"N·m·s/rad": 1.0, "N·m/rad": 0.5, "N·m/(rad·s)": 1.0 / 3.0, "1/s": 1.0, "1/s²": 0.5}.get(
            unit
        )
        if power is None or not np.all(np.isfinite(array)):
            continue
        if unit.startswith("N·m"):
            if array.ndim == 3 and array.shape[1:] == (nv, nv):
                largest = float(np.max(np.abs(np.linalg.eigvals(minv @ array[0]))))
            elif array.size in (1, nv):
                largest = float(np.max(np.abs(np.linalg.eigvals(minv * np.ravel(array)[None, :]))))
            else:
                continue
        else:
            largest = float(np.max(np.abs(array)))
        rates[f.name] = largest**power
    return rates


def _cause(controller: Controller, lin: Linearisation, eigenvalue: complex, joint: int | None) -> str:
    """What sets the mode ``eigenvalue``: the plant's joint damping, a gain of the law, or the law."""
    rate = abs(eigenvalue)
    damping = np.diag(lin.damping)
    if damping.any():
        plant_rates = np.linalg.eigvals(np.linalg.solve(lin.inertia, damping)).real
        if plant_rates.max() >= 0.5 * rate:
            j = int(np.argmax(lin.damping / np.diag(lin.inertia)))
            return (
                f"the plant's joint damping: {lin.damping[j]:.3g} N·m·s/rad on joint {j + 1} over its inertia "
                f"{lin.inertia[j, j]:.3g} kg·m² (rate {plant_rates.max():.3g} 1/s)"
            )
    rates = _gain_rates(controller, lin.inertia)
    close = {name: r for name, r in rates.items() if r > 0 and abs(math.log(r / rate)) < math.log(3.0)}
    if close:
        name = min(close, key=lambda n: abs(math.log(close[n] / rate)))
        spec = gain_spec(next(f for f in dataclasses.fields(controller.gains) if f.name == name))
        unit = f" [{spec.unit}]" if spec.unit else ""
        against = " on the arm's inertia M(q(0))" if spec.unit.startswith("N·m") else ""
        return f"the law's gain {name}{unit} (its rate{against}: {close[name]:.3g} 1/s)"
    if not np.abs(lin.law[: lin.inertia.shape[0]]).any():  # the law feeds nothing back: the arm's own
        return "the arm's own dynamics at the start (the law feeds nothing back)"
    kind = "velocity" if abs(eigenvalue.imag) < abs(eigenvalue.real) else "position"
    where = f" on joint {joint + 1}" if joint is not None else " on its state z"
    return f"the law's {kind} feedback{where} (its linearisation by finite differences)"


def check_step(
    controller: Controller, plant: Plant, trajectory: Trajectory, config: SimulationConfig
) -> StepCheck:
    """The step of ``config`` checked against the fastest mode of the run's start (one run: the
    first row of per-run gains). See the module docstring for the bounds."""
    dt = config.duration / config.steps
    period_steps = config.hold_steps or (1 if plant.delay > 0 else None)
    if config.method != "rk4":
        return StepCheck(
            True, config.method, dt, math.inf, 0j, None, "an adaptive step has no stability bound"
        )
    lin = linearise(controller, plant, initial_law_input(controller, plant, trajectory, config))
    if not np.isfinite(lin.A).all():  # e.g. a plan the law could not make at t = 0: the run says why
        return StepCheck(
            True, "rk4", dt, math.inf, 0j, None, "not checked: the law is not finite near the start"
        )
    eigenvalues = np.linalg.eigvals(lin.A)
    if period_steps is None:
        stage = dt * eigenvalues
        growth = rk4_amplification(stage)
        bad = (eigenvalues.real <= 1e-9 * np.abs(eigenvalues)) & (growth > 1.0 + GROWTH_TOLERANCE)
        largest, bound = (math.inf, 0j) if not bad.any() else _largest_stage_step(eigenvalues)
        stable, method, step = not bad.any(), "rk4", dt
    else:
        step = dt * period_steps
        stable = _sampled_stable(sampled_radius(lin, dt, period_steps), eigenvalues, step)
        largest = math.inf if stable else _largest_period(lin, eigenvalues, dt, period_steps)
        bound = complex(eigenvalues[int(np.argmax(np.abs(eigenvalues)))]) if eigenvalues.size else 0j
        method = f"rk4, the law sampled every {step:g} s"
    if stable:
        fastest = complex(eigenvalues[int(np.argmax(np.abs(eigenvalues)))]) if eigenvalues.size else 0j
        return StepCheck(True, method, step, largest, fastest, None, "")
    joint = _joint_of(lin, bound)
    return StepCheck(False, method, step, largest, bound, joint, _cause(controller, lin, bound, joint))


def refusal(check: StepCheck, controller: Controller, dt: float) -> StepTooLargeError:
    """The one-line refusal of an unstable step (:class:`~twolink_pin.errors.StepTooLargeError`)."""
    lam, robot = check.eigenvalue, controller.robot
    kind = "real" if abs(lam.imag) < 1e-9 * abs(lam) else f"oscillating at {abs(lam.imag):.3g} rad/s"
    moves = ""
    if check.joint is not None:
        moves = f", moving joint {check.joint + 1} ({robot.model.names[check.joint + 1]}) most"
    sampled = check.method != "rk4"
    if sampled:
        bound = "the law held over each period, RK4 between its samples, is unstable on it"
    else:
        radius = rk4_radius(lam)
        bound = (
            f"RK4 is stable to {radius:.4g}/dt = {radius / dt:.3g} 1/s on it ({RK4_REAL_AXIS:.4g}/dt on the real "
            f"axis, {RK4_IMAGINARY_AXIS:.4g}/dt on the imaginary)"
        )
    largest = _rounded_down(check.largest_step)
    at_most = f"at most {largest:.2g} s" if largest > 0 else "a smaller one"
    expected = (
        f"{at_most} for '{controller.name}' on {robot.name}: at the start its fastest mode decays at "
        f"{abs(lam):.3g} 1/s ({kind}){moves}, set by {check.cause}; {bound}"
        + ("; or lower that gain" if check.cause.startswith("the law's gain") else "")
    )
    return StepTooLargeError("--control-period" if sampled else "--dt", check.step, expected)


class CheckTimeout(ControllerError):
    """A law that did not return within the run's wall-clock bound while its step was checked."""

    @classmethod
    def of(cls, error: ControllerError) -> CheckTimeout:
        """``error`` (:func:`~twolink_pin.simulation.deadline.timed_out`'s) as this class."""
        return cls(error.controller, error.time, error.detail)


def _rounded_down(x: float) -> float:
    """``x`` rounded down to 2 significant digits."""
    if not math.isfinite(x) or x <= 0:
        return x
    scale = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.floor(x / scale) * scale


def require_stable_step(
    controller: Controller, plant: Plant, trajectory: Trajectory, config: SimulationConfig
) -> StepCheck | None:
    """:func:`check_step`, raising its refusal when the step is not stable; None when the check
    could not be made (a law that raises or returns something unusable on the perturbed states,
    or cannot be copied: the run itself then says what is wrong)."""
    if not config.check_step or config.method != "rk4" or not plant.law_per_stage:
        return None  # DOP853 adapts; MuJoCo's own Euler/implicitfast steps are not the engine's RK4
    try:  # within the run's wall-clock bound (--timeout): a law that never returns stops here
        with bounded(lambda seconds: CheckTimeout.of(timed_out(controller, 0.0, seconds))):
            check = check_step(controller, plant, trajectory, config)
    except (StepTooLargeError, CheckTimeout):
        raise
    except Exception:  # a user's law the linearisation cannot evaluate: the run will say why
        return None
    if not check.stable:
        raise refusal(check, controller, config.duration / config.steps)
    return check
