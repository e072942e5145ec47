"""``numpy.linalg.solve`` and ``numpy.linalg.inv`` for the small stacked matrices of a law's
evaluation, without their per-call Python wrapper, bit for bit the same.

The engine evaluates a task-space law four times per RK4 step on (1, 7, 7) matrices; there
``numpy.linalg.solve``'s wrapper (argument conversion and checks, type promotion) cost more
than the LAPACK call itself. The functions here call the same generalized ufunc
(``numpy.linalg._umath_linalg``: the same LAPACK routine, so the same bits) on float64
arrays under the same ``errstate`` as ``numpy.linalg`` (a singular matrix raises
``LinAlgError("Singular matrix")``), and leave any other input (another dtype, a 1-D
right-hand side, not an ndarray) to ``numpy.linalg`` itself.

If numpy's private module is missing (another numpy), both are ``numpy.linalg``'s own.
"""

from __future__ import annotations

from typing import Any

import numpy as np

try:  # numpy's own gufuncs behind numpy.linalg (private: guarded, with numpy.linalg as fallback)
    from numpy.linalg import _umath_linalg

    _SOLVE: Any = _umath_linalg.solve
    _INV: Any = _umath_linalg.inv
except (ImportError, AttributeError):  # pragma: no cover - numpy without the module
    _SOLVE = _INV = None

_FLOAT = np.dtype(np.float64)


def _singular(err: str, flag: int) -> None:
    """numpy.linalg's errstate callback: LAPACK met a zero pivot."""
    raise np.linalg.LinAlgError("Singular matrix")


def solve(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``numpy.linalg.solve(a, b)`` for stacked (…, n, n) ``a`` and (…, n, k) ``b``."""
    if (
        _SOLVE is not None
        and type(a) is np.ndarray
        and type(b) is np.ndarray
        and a.dtype is _FLOAT
        and b.dtype is _FLOAT
        and a.ndim == b.ndim >= 2
        and a.shape[-1] == a.shape[-2]
    ):
        with np.errstate(call=_singular, invalid="call", over="ignore", divide="ignore", under="ignore"):
            return _SOLVE(a, b)
    return np.linalg.solve(a, b)


def inv(a: np.ndarray) -> np.ndarray:
    """``numpy.linalg.inv(a)`` for stacked (…, n, n) ``a``."""
    if (
        _INV is not None
        and type(a) is np.ndarray
        and a.dtype is _FLOAT
        and a.ndim >= 2
        and a.shape[-1] == a.shape[-2]
    ):
        with np.errstate(call=_singular, invalid="call", over="ignore", divide="ignore", under="ignore"):
            return _INV(a)
    return np.linalg.inv(a)


__all__ = ["inv", "solve"]
