"""The reference ahead of each evaluation, for a law that declares
:meth:`~twolink_pin.controllers.Controller.preview_times`.

The engine samples the joint reference where it samples it for ``q_des`` (the half-step grid
of a block) and, for such a law, also at ``t + s_j`` for the law's offsets ``s_j``: one
``trajectory.sample`` call per block for all of its ``(half-steps × P)`` times, read-only
rows of shape (1, P, nv) (the same for every run of a batch), handed to the law in
:attr:`LawInput.preview <twolink_pin.controllers.LawInput.preview>` as a
:class:`~twolink_pin.controllers.ReferencePreview`. Any other law gets ``None`` there.

A law that plans (:meth:`~twolink_pin.controllers.Controller.update_period`) gets the
preview where it plans: at its update instants (in ``update`` and in ``compute`` there), and
``None`` at the evaluations between, which follow the plan — sampling ``P`` times ahead of
every RK4 stage would cost a retimed reference 13 % of ``mpc``'s run for samples it never reads.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from twolink_pin.controllers import Controller
from twolink_pin.controllers.preview import ReferencePreview, checked_preview_times
from twolink_pin.simulation.containment import read_only
from twolink_pin.trajectory import Trajectory


def preview_offsets(controller: Controller) -> np.ndarray | None:
    """The law's preview offsets [s], (P,) read-only, or None (it asks for none).

    Raises:
        InvalidParameterError: offsets that are not finite numbers >= 0 (naming the law).
    """
    return checked_preview_times(controller)


def previews(
    offsets: np.ndarray | None,
    trajectory: Trajectory | None,
    t: np.ndarray,
    at: np.ndarray | None = None,
) -> Sequence[ReferencePreview | None]:
    """Per evaluation time ``t`` [s] (K,), the reference at ``t + offsets``: K
    :class:`~twolink_pin.controllers.ReferencePreview` (arrays (1, P, nv), read-only), or K
    ``None`` when the law asks for none (or there is no trajectory to sample). ``at``: (K,)
    bool, the evaluations that get one (the others ``None``); None: every one."""
    t = np.asarray(t, dtype=float).reshape(-1)
    rows: list[ReferencePreview | None] = [None] * t.size
    if offsets is None or trajectory is None:
        return rows
    where = np.arange(t.size) if at is None else np.flatnonzero(at)
    if not where.size:
        return rows
    times = t[where, None] + offsets[None, :]  # (K', P)
    sample = trajectory.sample(times.reshape(-1))
    k, p = times.shape
    q, v, a = (
        read_only(np.ascontiguousarray(np.reshape(x, (k, 1, p, -1)))) for x in (sample.q, sample.v, sample.a)
    )
    times = read_only(times)
    for j, i in enumerate(where.tolist()):
        rows[i] = ReferencePreview(times[j], q[j], v[j], a[j])
    return rows
