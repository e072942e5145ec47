"""The engine: N ≥ 1 runs of one law on one plant, advanced together by fixed-step RK4.

State ``x = (q, q̇, z)`` per run (``z``: the law's internal state), arrays ``(N, ·)``.

* **Per-stage law** (default): classical RK4, the law evaluated at every stage, the
  reference sampled on the half-step grid.
* **Sampled law** (``control_period`` = m steps): the law is evaluated once every m steps
  at the state of that instant and its output — τ and ż — held (zero-order hold) until the
  next sample; RK4 integrates the plant under the held torque and ``z ← z + dt ż`` per
  step. This is what a digital controller does; it differs from the per-stage law by
  O(control_period).

A plant that pushes back (:mod:`twolink_pin.disturbances`: a wrench, a payload step,
sensor noise, a delay) runs in the same loop: :class:`~twolink_pin.simulation.events.PlantEvents`
gives each step's dynamics and the noise on what the law measures, and with a delay the law is
sampled every step (or control period) and a :class:`~twolink_pin.simulation.events.DelayLine`
applies its torque ``delay`` steps late (details in :mod:`twolink_pin.simulation.events`).

The law gets its Pinocchio terms from :func:`~twolink_pin.simulation.terms.terms_for`
and the plant's accelerations come from :func:`~twolink_pin.simulation.forward.dynamics_for`
(one ABA per run and stage). Output samples are written block by block (:data:`BLOCK`
steps): into the full record when ``record=True``, else into a small buffer handed to an
observer (e.g. running metrics) — memory then stays O(N), whatever the duration.

After every block each run's state is checked: a run whose state is non-finite or beyond
:data:`~twolink_pin.simulation.config.DIVERGENCE_LIMIT` has diverged at the first such
sample; so has a run whose law returned a non-finite torque. With ``stop_on_divergence``
(single runs) that raises; otherwise the run is parked on the reference and flagged in
:attr:`EngineRun.diverged_at` while the others go on. A law that raises, or returns the
wrong type or shape, stops the run with :class:`~twolink_pin.errors.ControllerError`
naming the law and the simulated time.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple, Protocol

import numpy as np

from twolink_pin.controllers import Controller, LawInput, LawOutput
from twolink_pin.errors import ControllerError, SimulationDivergedError, TwolinkPinError, raised_at
from twolink_pin.plant import Plant
from twolink_pin.simulation.config import DIVERGENCE_LIMIT, SimulationConfig
from twolink_pin.simulation.containment import contained, read_only
from twolink_pin.simulation.deadline import bounded, run_watcher, timed_out
from twolink_pin.simulation.events import DelayLine, PlantEvents
from twolink_pin.simulation.forward import dynamics_for
from twolink_pin.simulation.task_reference import reference_rows
from twolink_pin.simulation.terms import terms_for
from twolink_pin.trajectory import Trajectory

BLOCK = 128
"""Steps per block: how often states are checked and unrecorded samples handed on."""


class Samples(NamedTuple):
    """A block of consecutive output samples of N runs (B samples)."""

    start: int
    """Index of the first sample (sample k is at ``t = k dt``)."""
    t: np.ndarray
    """Times [s], shape (B,)."""
    q: np.ndarray
    """Joint positions [rad], shape (B, N, nv)."""
    v: np.ndarray
    """Joint velocities [rad/s], shape (B, N, nv)."""
    z: np.ndarray
    """The law's state, shape (B, N, nz)."""
    tau_command: np.ndarray
    """Commanded torque [N·m], shape (B, N, nv) (the law's output at the sample)."""
    q_des: np.ndarray
    """Reference positions [rad], shape (B, 1, nv)."""
    v_des: np.ndarray
    """Reference velocities [rad/s], shape (B, 1, nv)."""
    a_des: np.ndarray
    """Reference accelerations [rad/s²], shape (B, 1, nv)."""
    q_measured: np.ndarray | None = None
    """The positions the law measured [rad] (``q`` + sensor noise), shape (B, N, nv); None
    without sensor noise (the law measures ``q``) or outside the full record."""
    v_measured: np.ndarray | None = None
    """The velocities the law measured [rad/s], as ``q_measured``."""


class Observer(Protocol):
    """Receives every block of samples as the engine writes it."""

    def add(self, samples: Samples) -> None: ...


class EngineRun(NamedTuple):
    """What :func:`integrate` returns."""

    t: np.ndarray
    """Output times [s], shape (K,)."""
    record: Samples | None
    """Every sample (``record=True``), else None."""
    z_final: np.ndarray
    """The law's state at the end, shape (N, nz) (diverged runs: their parked state)."""
    diverged_at: np.ndarray
    """Time [s] each run diverged, NaN if it did not, shape (N,)."""
    detail: tuple[str | None, ...]
    """What was detected for each diverged run, None for the others."""


def _validate(controller: Controller, out: object, runs: int, nv: int, nz: int, t: float) -> None:
    name = controller.name
    if not isinstance(out, LawOutput):
        raise ControllerError(
            name, t, f"compute returned {type(out).__name__}; return LawOutput(tau) or LawOutput(tau, dz)"
        )
    for label, value, width in (("tau", out.tau, nv), ("dz", out.dz, nz)):
        if value is None and label == "dz" and nz == 0:
            continue
        shape = getattr(value, "shape", None)
        if not isinstance(value, np.ndarray) or shape != (runs, width):
            got = f"shape {shape}" if shape is not None else type(value).__name__
            raise ControllerError(name, t, f"LawOutput.{label} must have shape ({runs}, {width}), got {got}")
        if value.dtype.kind not in "fiu":  # complex, bool, str, object: not a torque Pinocchio takes
            raise ControllerError(
                name,
                t,
                f"LawOutput.{label} holds {value.dtype} values; expected real numbers (float64)"
                + (f", e.g. {label}.real if the imaginary part is zero" if value.dtype.kind == "c" else ""),
            )


def _bad_rows(x: np.ndarray) -> np.ndarray:
    """(B, N) mask: the sample's entries are non-finite or beyond the divergence limit."""
    if x.shape[-1] == 0:
        return np.zeros(x.shape[:2], dtype=bool)
    return ~(np.abs(x) < DIVERGENCE_LIMIT).all(axis=-1)


def integrate(
    controller: Controller,
    plant: Plant,
    trajectory: Trajectory,
    config: SimulationConfig,
    q0: np.ndarray,
    v0: np.ndarray,
    z0: np.ndarray,
    *,
    record: bool,
    observer: Observer | None = None,
    threads: int | None = None,
    stop_on_divergence: bool = False,
    progress: Callable[[int, int], None] | None = None,
) -> EngineRun:
    """Advance N runs of ``controller`` on ``plant`` along ``trajectory`` (see module doc).

    Args:
        controller: The law (one object for all runs; its per-run gains broadcast).
        plant: The arm all runs drive.
        trajectory: The reference.
        config: Duration, step, control period (``method`` is not used: RK4).
        q0: Initial positions [rad], shape (N, nv).
        v0: Initial velocities [rad/s], shape (N, nv).
        z0: Initial law state, shape (N, nz).
        record: Keep every sample (:attr:`EngineRun.record`).
        observer: Receives each block of samples.
        threads: Threads for Pinocchio's parallel algorithms (N > 1).
        stop_on_divergence: Raise :class:`SimulationDivergedError` at the first diverged
            run instead of parking it.
        progress: Called as ``progress(steps_done, steps_total)`` after each block.
    """
    runs, nv = q0.shape
    nz = z0.shape[1]
    name = controller.name
    n = config.steps
    dt = config.duration / n
    hold = config.hold_steps
    new = tuple.__new__  # LawInput(...) through tuple.__new__ (see below)
    terms = terms_for(controller, runs, threads)
    # A plant that pushes back (wrench, payload step, sensor noise, delay): its events
    # choose the dynamics of each step, offset what the law measures, delay its torque.
    events = PlantEvents(plant, runs, threads, nv) if plant.has_events else None
    line = DelayLine(plant.delay) if plant.delay > 0 else None
    accel = dynamics_for(plant, runs, threads) if events is None else events.accel_at(0.0)
    noise: list[np.ndarray] = []  # the current step's offsets on (q, q̇) with sensor noise
    compute = _law_call(controller, noise if events is not None and events.noise is not None else None)
    sampled = hold is not None or line is not None  # the law evaluated once per step or period
    every = hold if hold is not None else 1
    total = n + 1
    size = total if record else min(total, BLOCK)
    Q, V, T = (np.empty((size, runs, nv)) for _ in range(3))
    Z = np.empty((size, runs, nz))
    RQ, RV, RA = (np.empty((size, 1, nv)) for _ in range(3))
    measured = record and events is not None and events.noise is not None
    MQ, MV = (np.empty((size, runs, nv)) for _ in range(2)) if measured else (None, None)
    times = np.arange(total) * dt
    diverged_at = np.full(runs, np.nan)
    detail: list[str | None] = [None] * runs
    alive = np.ones(runs, dtype=bool)
    z_start = np.array(z0, dtype=float)
    q, v, z = np.array(q0, dtype=float), np.array(v0, dtype=float), z_start.copy()
    # The steps as (1, width) rows: numpy multiplies two 2-D operands on its fast path, while
    # a Python float (or a 1-D row) against a (1, nv) array costs twice as much at N = 1.
    steps = _Steps(
        dt,
        *(np.full((1, nv), x) for x in (dt, dt / 2, dt / 6, 2.0)),
        *(np.full((1, nz), x) for x in (dt, dt / 2, dt / 6, 2.0)),
    )
    no_state = np.zeros((runs, 0))

    # LawInput(...) through tuple.__new__ (``new`` above): the NamedTuple's own __new__ is a
    # Python function that costs twice as much, four times a step.
    # The law's outputs: dz is an (N, nz) array whenever nz > 0 (checked at the first evaluation).
    tau1: Any = None
    dz1: Any = None
    first = True
    clock = _Clock()  # time of the law evaluation under way (for error messages)
    watcher = run_watcher()
    # A diverging run overflows before its block is checked. The run is bounded in wall-clock
    # time (--timeout, simulation.deadline): past it, an error naming the law at t = now.
    with np.errstate(all="ignore"), bounded(lambda seconds: timed_out(controller, clock.now, seconds)):
        for k0 in range(0, total, BLOCK):
            k1 = min(k0 + BLOCK, total)
            rq, rv, ra, ref = _block_reference(controller, trajectory, k0, k1, n, dt)
            if events is not None:
                events.draw(k0, k1)
            off = 0 if record else k0
            filled = k0 - off
            try:
                for k in range(k0, k1):
                    i = 2 * (k - k0)
                    t = k * dt
                    if events is not None:
                        accel = events.accel_at(t)
                        if events.noise is not None:
                            noise[:] = events.noise_at(k)
                    if not sampled or k % every == 0:
                        clock.now = t
                        out = compute(new(LawInput, (t, q, v, z, *ref[i])), terms)
                        if first:
                            _validate(controller, out, runs, nv, nz, t)
                            first = False
                        tau1, dz1 = out.tau, (out.dz if nz else no_state)
                        if line is not None:
                            line.push(k, tau1, dz1)
                    tau_k, dz_k = (tau1, dz1) if line is None else line.at(k)  # the torque applied
                    b = k - off
                    Q[b], V[b], T[b] = q, v, tau_k
                    if MQ is not None and MV is not None:
                        MQ[b], MV[b] = q + noise[0], v + noise[1]  # as the law measured it
                    if nz:
                        Z[b] = z
                    filled = b + 1
                    if k == n:
                        break
                    if sampled:  # zero-order hold (or delay): τ and ż fixed over the step
                        q, v, z = _held_step(accel, q, v, z, tau_k, dz_k, steps, nz)
                    else:
                        q, v, z = _stage_step(
                            compute, terms, accel, q, v, z, tau_k, dz_k, ref, i, t, steps, nz, clock
                        )
            except (KeyboardInterrupt, SystemExit, MemoryError):
                raise
            except Exception as exc:
                if not _raised_by(exc, compute):
                    raise
                # A law may raise on a state that had already diverged: report the divergence.
                _flag_block(Q, V, Z, T, k0 - off, filled, times, off, alive, diverged_at, detail, name, True)
                if isinstance(exc, ControllerError):
                    raise
                what = str(exc) if isinstance(exc, TwolinkPinError) else f"{type(exc).__name__}: {exc}"
                raise ControllerError(name, clock.now, what + raised_at(exc, controller)) from exc
            rows = slice(k0 - off, k1 - off)
            RQ[rows], RV[rows], RA[rows] = (x[: 2 * (k1 - k0) : 2] for x in (rq, rv, ra))
            newly = _flag_block(
                Q,
                V,
                Z,
                T,
                k0 - off,
                k1 - off,
                times,
                off,
                alive,
                diverged_at,
                detail,
                name,
                stop_on_divergence,
            )
            if k1 <= n:  # the state after the block's last step is sample k1
                late = _late_divergence(
                    q, v, z, alive, k1 * dt, diverged_at, detail, name, stop_on_divergence
                )
                newly |= late
                if newly.any():  # park them on the reference, keep the batch going
                    j = 2 * (k1 - k0)
                    q, v, z = q.copy(), v.copy(), z.copy()  # the law saw them read-only
                    q[newly], v[newly], z[newly] = rq[j][0], rv[j][0], z_start[newly]
            if observer is not None or watcher is not None:
                block = Samples(
                    k0, times[k0:k1], Q[rows], V[rows], Z[rows], T[rows], RQ[rows], RV[rows], RA[rows]
                )
                if observer is not None:
                    observer.add(block)
                if watcher is not None:  # simulation.deadline.watched: may raise RunCancelled
                    watcher(block)
            if progress is not None:
                progress(min(k1, n), n)
    recorded = Samples(0, times, Q, V, Z, T, RQ, RV, RA, MQ, MV) if record else None
    return EngineRun(times, recorded, z, diverged_at, tuple(detail))


def _block_reference(
    controller: Controller, trajectory: Trajectory, k0: int, k1: int, n: int, dt: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Any]:
    """The reference of steps ``k0 … k1 − 1`` on the half-step grid: ``q_des``, ``q̇_des``,
    ``q̈_des`` as read-only (H, 1, nv) rows and the law's input rows (task fields included)."""
    last_half = min(2 * k1, 2 * n)  # the last stage of step k1 - 1 is at half-step 2 k1
    half_t = np.arange(2 * k0, last_half + 1) * (dt / 2)
    half = trajectory.sample(half_t)
    # Shared with later steps: the law can't write. C-contiguous rows: a trajectory may
    # sample column-major, and a strided (1, nv) row takes numpy's slow broadcasting
    # path in every operation of the law and the Terms that touches it.
    rq, rv, ra = (read_only(np.ascontiguousarray(x)[:, None, :]) for x in (half.q, half.v, half.a))
    return rq, rv, ra, reference_rows(controller, trajectory, half_t, half, rq, rv, ra)


class _Clock:
    """The simulated time of the law evaluation under way [s] (error messages, ``--timeout``)."""

    now = 0.0


class _Steps(NamedTuple):
    """The step's factors as (1, width) rows: numpy multiplies two 2-D operands on its fast
    path, while a Python float (or a 1-D row) against a (1, nv) array costs twice as much at N = 1."""

    dt: float
    h: np.ndarray
    h2: np.ndarray
    h6: np.ndarray
    two: np.ndarray
    hz: np.ndarray
    h2z: np.ndarray
    h6z: np.ndarray
    twoz: np.ndarray


def _stage_step(
    compute: Callable[[Any, Any], Any],
    terms: Any,
    accel: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    tau1: np.ndarray,
    dz1: np.ndarray,
    ref: Any,
    i: int,
    t: float,
    steps: _Steps,
    nz: int,
    clock: _Clock,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One classical RK4 step from ``(q, v, z)`` at ``t`` with the law at every stage (its first
    output ``tau1``, ``dz1`` given; ``ref[i]``: the reference rows of half-step i)."""
    new = tuple.__new__  # LawInput(...) through tuple.__new__: twice as cheap as its __new__
    dt, h, h2, h6, two, hz, h2z, h6z, twoz = steps
    a1 = accel(q, v, tau1)
    clock.now = now = t + dt / 2
    q2, v2 = q + h2 * v, v + h2 * a1
    z2 = z + h2z * dz1 if nz else z
    tau2, dz2 = compute(new(LawInput, (now, q2, v2, z2, *ref[i + 1])), terms)
    a2 = accel(q2, v2, tau2)
    q3, v3 = q + h2 * v2, v + h2 * a2
    z3 = z + h2z * dz2 if nz else z
    tau3, dz3 = compute(new(LawInput, (now, q3, v3, z3, *ref[i + 1])), terms)
    a3 = accel(q3, v3, tau3)
    clock.now = now = t + dt
    q4, v4 = q + h * v3, v + h * a3
    z4 = z + hz * dz3 if nz else z
    tau4, dz4 = compute(new(LawInput, (now, q4, v4, z4, *ref[i + 2])), terms)
    a4 = accel(q4, v4, tau4)
    if nz:
        z = z + h6z * (dz1 + twoz * (dz2 + dz3) + dz4)
    return q + h6 * (v + two * (v2 + v3) + v4), v + h6 * (a1 + two * (a2 + a3) + a4), z


def _held_step(
    accel: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    tau: np.ndarray,
    dz: np.ndarray,
    steps: _Steps,
    nz: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One RK4 step of the plant under the held torque ``tau``; ``z ← z + dt ż``."""
    _, h, h2, h6, two, hz = steps[:6]
    a1 = accel(q, v, tau)
    q2, v2 = q + h2 * v, v + h2 * a1
    a2 = accel(q2, v2, tau)
    q3, v3 = q + h2 * v2, v + h2 * a2
    a3 = accel(q3, v3, tau)
    q4, v4 = q + h * v3, v + h * a3
    a4 = accel(q4, v4, tau)
    if nz:
        z = z + hz * dz
    return q + h6 * (v + two * (v2 + v3) + v4), v + h6 * (a1 + two * (a2 + a3) + a4), z


def _law_call(controller: Controller, noise: list[np.ndarray] | None) -> Callable[[Any, Any], Any]:
    """The law as the loop calls it: contained (read-only inputs; ``sys.exit`` and
    ``MemoryError`` name it) and, with sensor noise, measuring the state plus ``noise``
    (the list the loop fills with the current step's offsets)."""
    law = contained(controller)
    if noise is None:
        return law
    new = tuple.__new__

    def compute(x: LawInput, terms: Any) -> LawOutput:  # the law measures the state + noise
        t, q, v, z, *reference = x
        return law(new(LawInput, (t, q + noise[0], v + noise[1], z, *reference)), terms)

    return compute


def _raised_by(exc: BaseException, compute: Callable[..., object]) -> bool:
    """Whether ``exc`` was raised inside the law (its ``compute`` is on the traceback)."""
    code = getattr(getattr(compute, "__func__", compute), "__code__", None)
    tb = exc.__traceback__
    while tb is not None:
        if tb.tb_frame.f_code is code:
            return True
        tb = tb.tb_next
    return isinstance(exc, ControllerError)


def _late_divergence(
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    alive: np.ndarray,
    t: float,
    diverged_at: np.ndarray,
    detail: list[str | None],
    name: str,
    stop_on_divergence: bool,
) -> np.ndarray:
    """Flag the live runs whose state after a block (at ``t`` [s]) has diverged; returns them."""
    current = _bad_rows(q[None])[0] | _bad_rows(v[None])[0] | _bad_rows(z[None])[0]
    late = alive & current
    if late.any():
        if stop_on_divergence:
            raise SimulationDivergedError(name, t, _state_detail(q, v, z, late))
        for r in np.flatnonzero(late):
            diverged_at[r] = t
            detail[r] = _state_detail(q, v, z, np.eye(len(alive), dtype=bool)[r])
        alive &= ~late
    return late


def _state_detail(q: np.ndarray, v: np.ndarray, z: np.ndarray, mask: np.ndarray) -> str:
    values = np.concatenate([np.abs(q[mask]).ravel(), np.abs(v[mask]).ravel(), np.abs(z[mask]).ravel()])
    worst = float(np.max(values)) if values.size else math.nan
    if not math.isfinite(worst) or np.isnan(values).any():
        return "non-finite state"
    return f"|state| = {worst:.3g} > {DIVERGENCE_LIMIT:g}"


def _flag_block(
    Q: np.ndarray,
    V: np.ndarray,
    Z: np.ndarray,
    T: np.ndarray,
    start: int,
    stop: int,
    times: np.ndarray,
    off: int,
    alive: np.ndarray,
    diverged_at: np.ndarray,
    detail: list[str | None],
    name: str,
    raise_now: bool,
) -> np.ndarray:
    """Flag the runs that diverged within buffer rows ``start:stop``; returns them."""
    rows = slice(start, stop)
    state_bad = _bad_rows(Q[rows]) | _bad_rows(V[rows]) | _bad_rows(Z[rows])
    torque_bad = ~np.isfinite(T[rows]).all(axis=-1)
    bad = (state_bad | torque_bad) & alive[None, :]
    newly = bad.any(axis=0)
    for r in np.flatnonzero(newly):
        first = int(np.argmax(bad[:, r]))
        k = start + first + off
        t = float(times[k])
        if torque_bad[first, r] and not state_bad[first, r]:
            what = f"the controller returned a non-finite torque τ = {T[start + first, r].tolist()}"
            if raise_now:
                raise ControllerError(name, t, what)
        else:
            what = _state_detail(
                Q[start + first], V[start + first], Z[start + first], np.eye(len(alive), dtype=bool)[r]
            )
            row = start + first
            if (
                row > 0
                and what == "non-finite state"
                and not (_bad_rows(Q[row - 1 : row]) | _bad_rows(V[row - 1 : row]))[0, r]
            ):
                what += (
                    f" one step after a sound state at t = {times[k - 1]:.6g} s: the controller's torque"
                    " or the plant produced NaN or inf within that step"
                )
            if raise_now:
                raise SimulationDivergedError(name, t, what)
        diverged_at[r] = t
        detail[r] = what
    alive &= ~newly
    return newly
