"""The adaptive-step method for one run: scipy's ``solve_ivp`` (DOP853) on the same law.

The right-hand side evaluates the law (through the same :class:`~twolink_pin.controllers.Terms`
as the fixed-step engine, with N = 1) and the plant's ABA; output on the fixed grid
``t_k = k dt``. Coulomb friction must use a smooth sign (``Friction.smoothing > 0``): an
exact ``sgn`` makes the step size collapse when a joint sticks. A collapsing step is
bounded (:data:`~twolink_pin.simulation.config.MAX_EVALUATIONS_PER_STEP` evaluations per
output interval) and, sooner, by the progress it makes: every :data:`PROGRESS_WINDOW`
evaluations the run's pace so far (evaluations per simulated second) is projected to its end,
and a run that would exceed the budget ends there, naming the time and the step it is down to
(a stiff law, e.g. ``--lambda 1e5``, whose step is held at a fraction of ``dt`` by stability,
not accuracy) — a divergence report within seconds, never minutes of work that must fail.
"""

from __future__ import annotations

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.errors import ControllerError, SimulationDivergedError, TwolinkPinError, raised_at
from twolink_pin.plant import Plant
from twolink_pin.simulation.config import DIVERGENCE_LIMIT, MAX_EVALUATIONS_PER_STEP, SimulationConfig
from twolink_pin.simulation.containment import check_output, contained
from twolink_pin.simulation.deadline import bounded, timed_out
from twolink_pin.simulation.engine import Samples
from twolink_pin.simulation.forward import dynamics_for
from twolink_pin.simulation.task_reference import law_input
from twolink_pin.simulation.terms import SingleRunTerms
from twolink_pin.trajectory import Trajectory

PROGRESS_WINDOW = 20_000
"""Evaluations between two checks that the adaptive step still makes progress."""
EVALUATIONS_PER_STEP = 12
"""Right-hand-side evaluations of one DOP853 step (to name the step size a pace implies)."""


def projected_evaluations(calls: int, time: float, start: float, end: float) -> float:
    """Evaluations the whole run ``[start, end]`` [s] needs at the pace so far (``calls`` to reach
    ``time``); infinite when no time has passed."""
    elapsed = time - start
    return calls * (end - start) / elapsed if elapsed > 0 else float("inf")


def check_progress(
    name: str, calls: int, budget: int, time: float, span: tuple[float, float], dt: float, x: np.ndarray
) -> None:
    """Raise :class:`SimulationDivergedError` naming ``time`` [s] when the run has used its
    ``budget`` of evaluations, when its pace so far projected to the end of ``span`` [s] would
    exceed it (checked every :data:`PROGRESS_WINDOW` evaluations), or when the state ``x``
    left the bounds."""
    if calls > budget:  # a collapsing step size: stiff or diverging, never a hang
        raise SimulationDivergedError(
            name,
            time,
            f"the adaptive step collapsed ({budget} evaluations); the problem is too stiff for DOP853",
        )
    if calls % PROGRESS_WINDOW == 0 and projected_evaluations(calls, time, *span) > budget:
        step = EVALUATIONS_PER_STEP * (time - span[0]) / calls
        raise SimulationDivergedError(
            name,
            time,
            f"the adaptive step collapsed to about {step:.2g} s ({dt / max(step, 1e-300):.3g} steps per "
            f"dt = {dt:g} s): at this pace the run needs more than the {budget} evaluations allowed "
            f"({MAX_EVALUATIONS_PER_STEP} per dt); the problem is too stiff for DOP853 (use --method "
            "rk4 with a smaller --dt, or smaller gains)",
        )
    if not np.all(np.abs(x) < DIVERGENCE_LIMIT):
        raise SimulationDivergedError(
            name,
            time,
            "non-finite state" if not np.all(np.isfinite(x)) else f"|state| > {DIVERGENCE_LIMIT:g}",
        )


def _law_error(exc: Exception, controller: Controller, time: float) -> ControllerError:
    """The error naming the law for what its call at ``time`` [s] raised: a refusal of the
    package (:class:`TwolinkPinError`) by its message, anything else by its type, message and line."""
    if isinstance(exc, TwolinkPinError):
        return ControllerError(controller.name, time, str(exc))
    return ControllerError(controller.name, time, f"{type(exc).__name__}: {exc}{raised_at(exc, controller)}")


def integrate_adaptive(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    q0: np.ndarray,
    v0: np.ndarray,
    z0: np.ndarray,
) -> Samples:
    """One run by DOP853 with error control; every output sample (shapes as the engine's, N = 1).

    Raises:
        SimulationDivergedError: the state left the bounds, or the step size collapsed.
        ControllerError: the law raised or returned the wrong shape.
    """
    nv, nz = q0.shape[1], z0.shape[1]
    n, dt = config.steps, config.duration / config.steps
    t = np.arange(n + 1) * dt
    name = controller.name
    terms = SingleRunTerms(controller)
    accel = dynamics_for(plant, 1)
    budget = MAX_EVALUATIONS_PER_STEP * n + 10_000
    calls = 0

    compute = contained(controller)  # read-only inputs; sys.exit and MemoryError name the law

    last = [0.0]  # simulated time of the latest law evaluation

    def law(time: float, q: np.ndarray, v: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        last[0] = time
        ref = trajectory.sample(time)
        try:  # the reference rows the engine would give (task fields, preview)
            out = compute(
                law_input(controller, time, q, v, z, ref.q[None], ref.v[None], ref.a[None], trajectory), terms
            )
        except ControllerError:
            raise
        except Exception as exc:
            raise _law_error(exc, controller, time) from exc
        if calls <= 1:
            check_output(controller, out, 1, nv, nz, time)
        return out.tau, (out.dz if out.dz is not None else np.zeros((1, 0)))

    def rhs(time: float, x: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        check_progress(name, calls, budget, time, (t[0], t[-1]), dt, x)
        q, v, z = x[None, :nv], x[None, nv : 2 * nv], x[None, 2 * nv :]
        tau, dz = law(time, q, v, z)
        if not np.all(np.isfinite(tau)):
            raise ControllerError(
                name, time, f"the controller returned a non-finite torque τ = {tau[0].tolist()}"
            )
        return np.concatenate([v[0], accel(q, v, tau)[0], dz[0]])

    from scipy.integrate import solve_ivp  # with scipy.optimize 0.3 s to import: only for this method

    # bounded in wall-clock time (--timeout, simulation.deadline): past it, an error naming the law
    with (
        np.errstate(all="ignore"),
        bounded(lambda timeout: timed_out(controller, last[0], timeout), stall=True),
    ):
        sol = solve_ivp(
            rhs,
            (t[0], t[-1]),
            np.concatenate([q0[0], v0[0], z0[0]]),
            method="DOP853",
            t_eval=t,
            rtol=config.rtol,
            atol=config.atol,
        )
    if sol.status != 0:
        raise SimulationDivergedError(name, float(sol.t[-1]) if sol.t.size else 0.0, sol.message)
    x = sol.y.T
    q, v, z = x[:, None, :nv], x[:, None, nv : 2 * nv], x[:, None, 2 * nv :]
    ref = trajectory.sample(t)
    tau = np.array([law(float(t[k]), q[k], v[k], z[k])[0] for k in range(len(t))])
    return Samples(0, t, q, v, z, tau, ref.q[:, None, :], ref.v[:, None, :], ref.a[:, None, :])
