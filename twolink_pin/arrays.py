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


def readonly_or_none(array: npt.ArrayLike | None) -> np.ndarray | None:
    """:func:`readonly`, passing ``None`` through."""
    return None if array is None else readonly(array)
