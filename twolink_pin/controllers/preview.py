"""The reference ahead of now: what a law that plans may ask the engine for.

A law declares the times ahead at which it wants the reference —
:meth:`~twolink_pin.controllers.Controller.preview_times`, offsets ``s_j ≥ 0`` [s] from the
time of each evaluation (a model-predictive law: its knots ``0, h, …, K h``) — and the engine
samples its trajectory there at every evaluation, for every run of a batch at once (the
reference is the same for every run), and hands the samples in
:attr:`LawInput.preview <twolink_pin.controllers.LawInput.preview>` as a
:class:`ReferencePreview`. The law never holds the trajectory: a reference read from a file, a
retiming, an SE(3) path's joint solution are all previewed the same way, and a test can hand
a law any preview it likes. A law that declares none gets ``None`` there (and costs nothing).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from twolink_pin.errors import InvalidParameterError

MAX_PREVIEW = 10_000
"""Most preview times a law may ask for (each is sampled at every evaluation)."""


class ReferencePreview(NamedTuple):
    """The reference at the times a law asked for, ahead of an evaluation at ``t``: arrays
    batch-first like ``q_des`` (their leading axis is 1: the same for every run)."""

    t: np.ndarray
    """The times sampled [s], ``t + s_j`` for the law's offsets ``s_j``, shape (P,)."""
    q: np.ndarray
    """Reference positions [rad] at those times, shape (1, P, nv)."""
    v: np.ndarray
    """Reference velocities [rad/s], shape (1, P, nv)."""
    a: np.ndarray
    """Reference accelerations [rad/s²], shape (1, P, nv) (at a jump of a piecewise
    trajectory: the value its ``sample`` gives at that time)."""


def checked_preview_times(controller: Any) -> np.ndarray | None:
    """The law's :meth:`~twolink_pin.controllers.Controller.preview_times` as a read-only
    (P,) array of offsets [s], or None when it asks for none.

    Raises:
        InvalidParameterError: offsets that are not a non-empty 1-D sequence of at most
            :data:`MAX_PREVIEW` finite numbers ``>= 0`` (naming the law).
    """
    method = getattr(controller, "preview_times", None)
    given = method() if callable(method) else None
    if given is None:
        return None
    law = f"law {getattr(controller, 'name', type(controller).__name__)!r}: preview_times()"
    try:
        offsets = np.array(given, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(law, given, "offsets [s] >= 0 from now (a sequence of numbers)") from None
    if offsets.ndim != 1 or not 1 <= offsets.size <= MAX_PREVIEW:
        raise InvalidParameterError(
            law, f"shape {offsets.shape}", f"a 1-D sequence of 1 to {MAX_PREVIEW} offsets [s] from now"
        )
    if not (np.isfinite(offsets).all() and (offsets >= 0).all()):
        bad = int(np.flatnonzero(~(np.isfinite(offsets) & (offsets >= 0)))[0])
        raise InvalidParameterError(f"{law}[{bad}]", float(offsets[bad]), "a finite offset [s] >= 0 from now")
    offsets.setflags(write=False)
    return offsets
