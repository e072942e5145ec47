"""Read-only float arrays: how results and models hand out their data.

Every array a result or a model exposes is a private float copy with ``writeable=False``,
so a caller cannot change a run after the fact (``result.q[0] = 0`` raises ValueError).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def readonly(array: npt.ArrayLike) -> np.ndarray:
    """A read-only float copy of ``array``."""
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out


def readonly_masked(array: npt.ArrayLike, dead: np.ndarray | None) -> np.ndarray:
    """:func:`readonly` with the rows of ``dead`` runs (a boolean mask over the first axis, or
    None) set to NaN: a running statistic's value for the runs that diverged."""
    out = np.array(array, dtype=float)
    if dead is not None:
        out[dead] = np.nan
    out.setflags(write=False)
    return out


def readonly_or_none(array: npt.ArrayLike | None) -> np.ndarray | None:
    """:func:`readonly`, passing ``None`` through."""
    return None if array is None else readonly(array)
