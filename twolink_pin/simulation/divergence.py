"""What the engine checks after every block: which runs diverged, when, and what was seen.

A run has diverged at the first sample whose state ``(q, q̇, z)`` is non-finite or beyond
:data:`~twolink_pin.simulation.config.DIVERGENCE_LIMIT`, or whose commanded torque is
non-finite (the law's fault, named as such). A run the law gave up (its state or torque set
non-finite, :meth:`~twolink_pin.controllers.Controller.run_failure`) is reported with the law's
reason. :func:`flag_block` looks within a block of
written samples, :func:`late_divergence` at the state after the block's last step; both
record the time and a one-line detail per run, or raise at once (single runs).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from twolink_pin.errors import ControllerError, SimulationDivergedError
from twolink_pin.simulation.config import DIVERGENCE_LIMIT


def bad_rows(x: np.ndarray) -> np.ndarray:
    """(B, N) mask: the sample's entries are non-finite or beyond the divergence limit."""
    if x.shape[-1] == 0:
        return np.zeros(x.shape[:2], dtype=bool)
    return ~(np.abs(x) < DIVERGENCE_LIMIT).all(axis=-1)


def late_divergence(
    q: np.ndarray,
    v: np.ndarray,
    z: np.ndarray,
    alive: np.ndarray,
    t: float,
    diverged_at: np.ndarray,
    detail: list[str | None],
    name: str,
    stop_on_divergence: bool,
    why: Callable[[int], str | None] = lambda run: None,
    plant_why: Callable[[int], str | None] | None = None,
) -> np.ndarray:
    """Flag the live runs whose state after a block (at ``t`` [s]) has diverged; returns them
    (``why(run)``: the law's reason for a run it gave up, :func:`law_reason`; ``plant_why(run)``:
    the plant's own cause, added to the state's, :func:`with_plant`)."""
    current = bad_rows(q[None])[0] | bad_rows(v[None])[0] | bad_rows(z[None])[0]
    late = alive & current
    if late.any():
        if stop_on_divergence:
            first = int(np.flatnonzero(late)[0])
            given = why(first)
            if given is not None:
                raise ControllerError(name, t, given)
            raise SimulationDivergedError(name, t, with_plant(state_detail(q, v, z, late), plant_why, first))
        for r in np.flatnonzero(late):
            diverged_at[r] = t
            detail[r] = why(int(r)) or with_plant(
                state_detail(q, v, z, np.eye(len(alive), dtype=bool)[r]), plant_why, int(r)
            )
        alive &= ~late
    return late


def with_plant(detail: str, plant_why: Callable[[int], str | None] | None, run: int) -> str:
    """``detail`` with the plant's own cause of run ``run``'s failure, when it gives one."""
    cause = plant_why(run) if plant_why is not None else None
    return f"{detail}; {cause}" if cause else detail


def state_detail(q: np.ndarray, v: np.ndarray, z: np.ndarray, mask: np.ndarray) -> str:
    """What is wrong with the state of the runs in ``mask``: non-finite, or its largest entry."""
    values = np.concatenate([np.abs(q[mask]).ravel(), np.abs(v[mask]).ravel(), np.abs(z[mask]).ravel()])
    worst = float(np.max(values)) if values.size else math.nan
    if not math.isfinite(worst) or np.isnan(values).any():
        return "non-finite state"
    return f"|state| = {worst:.3g} > {DIVERGENCE_LIMIT:g}"


def flag_block(
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
    why: Callable[[int], str | None] = lambda run: None,
    plant_why: Callable[[int], str | None] | None = None,
) -> np.ndarray:
    """Flag the runs that diverged within buffer rows ``start:stop``; returns them
    (``why(run)``: the law's reason for a run it gave up, :func:`law_reason`; ``plant_why``: the
    plant's own cause of a state that diverged, :func:`with_plant`)."""
    rows = slice(start, stop)
    state_bad = bad_rows(Q[rows]) | bad_rows(V[rows]) | bad_rows(Z[rows])
    torque_bad = ~np.isfinite(T[rows]).all(axis=-1)
    bad = (state_bad | torque_bad) & alive[None, :]
    newly = bad.any(axis=0)
    for r in np.flatnonzero(newly):
        first = int(np.argmax(bad[:, r]))
        k = start + first + off
        t = float(times[k])
        given = why(int(r))
        if given is not None:  # the law gave this run up and says why
            if raise_now:
                raise ControllerError(name, t, given)
            what = given
        elif torque_bad[first, r] and not state_bad[first, r]:
            what = f"the controller returned a non-finite torque τ = {T[start + first, r].tolist()}"
            if raise_now:
                raise ControllerError(name, t, what)
        else:
            what = state_detail(
                Q[start + first], V[start + first], Z[start + first], np.eye(len(alive), dtype=bool)[r]
            )
            row = start + first
            if (
                row > 0
                and what == "non-finite state"
                and not (bad_rows(Q[row - 1 : row]) | bad_rows(V[row - 1 : row]))[0, r]
            ):
                what += (
                    f" one step after a sound state at t = {times[k - 1]:.6g} s: the controller's torque"
                    " or the plant produced NaN or inf within that step"
                )
            what = with_plant(what, plant_why, int(r))
            if raise_now:
                raise SimulationDivergedError(name, t, what)
        diverged_at[r] = t
        detail[r] = what
    alive &= ~newly
    return newly


def law_reason(controller: object) -> Callable[[int], str | None]:
    """``controller.run_failure`` as the checks ask it: a law's reason for giving up a run, or
    None (a law without the method, or whose method raises or returns no text: the state's own
    detail is reported instead)."""
    method = getattr(controller, "run_failure", None)

    def why(run: int) -> str | None:
        if method is None:
            return None
        try:
            text = method(run)
        except Exception:  # user code: a broken reason never hides the failure itself
            return None
        return text if isinstance(text, str) and text.strip() else None

    return why
