"""Matrix gains: a symmetric positive-definite ``K`` (k, k) of a law whose gain couples joints or
axes (``K = κ M(q₀)`` from the arm's inertia): how a value is read and checked
(:func:`validate_matrix`, :func:`as_matrix`) and how a law applies it (:func:`applied_form`,
:func:`applied_scalar`, :func:`gain_solve`). The gains' declaration is :mod:`twolink_pin.controllers.gains`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError

GAIN_RANGE = (1e-12, 1e12)
"""Smallest and largest magnitude of a nonzero gain (any unit): beyond them a gain is a typo,
and its products (``1/γ``, ``K s``) overflow."""


MATRIX_EXPECTED = (
    "a symmetric positive-definite matrix gain{unit}: a number s (s I), k numbers (a diagonal), "
    "k² numbers (a (k, k) matrix, row by row), a (k, k) matrix, or one (k, k) matrix per run (N, k, k)"
)
AXIS_SIZE = 3
"""k of a matrix gain declared ``per="axis"``: the world axes x, y, z."""


def _shown(matrix: np.ndarray) -> Any:
    """A matrix as its rows (nested lists), or its shape when large."""
    return matrix.tolist() if matrix.size <= 49 else f"a {matrix.shape} matrix"


def _check_matrices(name: str, array: np.ndarray, expected: str) -> np.ndarray:
    """``array`` (k, k) or (N, k, k) checked symmetric and positive definite, as a read-only
    (1 or N, k, k) stack; the error names the check that failed and the offending numbers."""
    stack = array.reshape(-1, *array.shape[-2:])
    for i, matrix in enumerate(stack):
        where = f"{name}[{i}]" if array.ndim == 3 else name
        scale = float(np.abs(matrix).max())
        skew = np.abs(matrix - matrix.T)
        if skew.max() > 1e-12 * scale:
            r, c = (int(x) for x in np.unravel_index(int(np.argmax(skew)), skew.shape))
            raise InvalidParameterError(
                where,
                _shown(matrix),
                f"{expected}; the symmetry check failed: it is not symmetric "
                f"(entry [{r}, {c}] = {matrix[r, c]:g} but [{c}, {r}] = {matrix[c, r]:g})",
            )
        eigenvalues = np.linalg.eigvalsh(matrix)
        try:
            np.linalg.cholesky(matrix)
        except np.linalg.LinAlgError:
            raise InvalidParameterError(
                where,
                _shown(matrix),
                f"{expected}; the positive-definite check failed: it is not positive definite "
                f"(eigenvalues {', '.join(f'{x:.4g}' for x in eigenvalues[:8])}"
                f"{', …' if eigenvalues.size > 8 else ''}; smallest {eigenvalues.min():.3g})",
            ) from None
        if not eigenvalues.min() >= GAIN_RANGE[0]:  # as a number s (s I) must be >= 1e-12
            raise InvalidParameterError(
                where,
                _shown(matrix),
                f"{expected}; the positive-definite check failed: its smallest eigenvalue "
                f"{eigenvalues.min():.3g} is below {GAIN_RANGE[0]:g}, the least a gain may be",
            )
    stack = np.ascontiguousarray(stack)
    stack.setflags(write=False)
    return stack


def _from_numbers(name: str, numbers: np.ndarray, k: int, expected: str) -> np.ndarray:
    """k numbers (a diagonal) or k² numbers (a (k, k) matrix, row by row) as a checked
    (1, k, k) matrix; any other count fails the shape check."""
    n = numbers.size
    if n == k:
        if not numbers.min() >= GAIN_RANGE[0]:
            raise InvalidParameterError(
                name,
                numbers.tolist(),
                f"{expected}; the positive-definite check failed: a diagonal entry is not > 0 "
                f"(smallest {numbers.min():g})",
            )
        return _check_matrices(name, np.diag(numbers), expected)
    if n == k * k:
        return _check_matrices(name, numbers.reshape(k, k), expected)
    raise InvalidParameterError(name, numbers.tolist(), f"{expected}; {shape_failed(n, k)}")


def validate_matrix(name: str, value: Any, unit: str = "", per: str = "joint") -> Any:
    """A matrix gain's value (:data:`MATRIX_EXPECTED`) checked: a number ``s`` (``s I``), a row of
    numbers whose reading waits for the law's k, or checked (1 or N, k, k) matrices. ``unit``: the
    gain's unit (in the message); ``per``: its declared shape (``"axis"``: k = 3, the world axes)."""
    expected = MATRIX_EXPECTED.format(unit=f" [{unit}]" if unit else "")
    if isinstance(value, bool):
        raise InvalidParameterError(name, value, expected)
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidParameterError(name, value, expected) from None
    if array.ndim == 2 and array.shape[1] == 1:  # one number per run (a sweep's draws): s_r I
        array = array[:, :, None]
    if array.ndim == 2 and array.shape[0] == 1 and per != "axis":  # numbers awaiting k, validated again
        array = array[0]
    if array.ndim > 3 or array.size == 0 or (array.ndim >= 2 and array.shape[-1] != array.shape[-2]):
        raise InvalidParameterError(
            name,
            f"array of shape {array.shape}",
            f"{expected}; the shape check failed: the last two axes of a matrix are equal",
        )
    if not np.all(np.isfinite(array)) or not np.all(np.abs(array) <= GAIN_RANGE[1]):
        raise InvalidParameterError(
            name, array.tolist() if array.size <= 36 else f"shape {array.shape}", expected
        )
    if array.ndim == 0:
        if not array >= GAIN_RANGE[0]:
            raise InvalidParameterError(name, float(array), expected)
        return float(array)
    if array.ndim == 1:
        if per == "axis":
            return _from_numbers(name, array, AXIS_SIZE, expected)
        side = math.isqrt(array.size)
        if side > 1 and side * side == array.size:  # k numbers or k² numbers: the law's k decides
            flat = array.reshape(1, -1)
            flat.setflags(write=False)
            return flat
        return _from_numbers(name, array, array.size, expected)
    return _check_matrices(name, array, expected)


def as_matrix(value: Any, k: int, name: str = "gain", unit: str = "") -> np.ndarray:
    """A validated matrix gain as ``(1, k, k)`` or ``(N, k, k)`` (a number s: ``s I``; a row
    of k or k² numbers: a diagonal or a matrix row by row, checked here)."""
    if isinstance(value, float):
        value = np.array(value).reshape(1, 1, 1)
    array = np.asarray(value)
    if array.ndim == 2:  # numbers whose reading needed k
        expected = MATRIX_EXPECTED.format(unit=f" [{unit}]" if unit else "")
        return _from_numbers(name, array[0], k, expected)
    if array.shape[1:] == (1, 1) and k != 1:
        array = array * np.eye(k)
        array.setflags(write=False)
    return array


def applied_form(matrix: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """A matrix gain ``(1 or N, k, k)`` (:func:`as_matrix`) as a law applies it: ``x ↦ K x`` for
    N runs (``x`` (N, k)), one C-level call (a ``functools.partial`` of a ufunc: no Python frame,
    several times per RK4 stage) — element-wise with the diagonals ``(1 or N, k)`` when every
    matrix is diagonal (the same operations, and bits, as a per-joint gain), else ``np.matvec``
    with the matrices."""
    array = np.asarray(matrix, dtype=float)
    k = array.shape[-1]
    if not np.any(array * (1.0 - np.eye(k))):
        diagonal = np.ascontiguousarray(array.diagonal(0, 1, 2))
        diagonal.setflags(write=False)
        return partial(np.multiply, diagonal)
    array = np.array(array)
    array.setflags(write=False)
    return partial(np.matvec, array)


def applied_scalar(value: Any) -> Any:
    """A scalar gain (a number, or one per run as an (N, 1) column: :mod:`~twolink_pin.controllers.gains`)
    as a law multiplies it into (N, k) arrays: a number as a read-only 0-d array — numpy's fast
    path at any N (a Python float costs 1.6 times as much at N = 1, a (1, k) row 8 times as much
    at N = 1000), the same products —, a column as it is."""
    if isinstance(value, np.ndarray):
        return value
    number = np.array(float(value))
    number.setflags(write=False)
    return number


def gain_solve(gain: Any, Y: np.ndarray) -> np.ndarray:
    """``K⁻¹ Y`` for one value set of a gain ``K`` (a number, per-joint values, or a matrix
    ``(1, k, k)``) and ``Y`` (k, …): a diagonal ``K`` divides row by row — the same operations
    (and bits) as a per-joint gain —, a full one is a linear solve."""
    array = np.asarray(gain, dtype=float)
    if array.ndim == 3:
        matrix = array[0]
        if np.any(matrix - np.diag(np.diag(matrix))):
            return np.linalg.solve(matrix, Y)
        array = np.diag(matrix)
    diagonal = np.broadcast_to(array.reshape(-1), (Y.shape[0],))
    return Y / diagonal.reshape((-1,) + (1,) * (Y.ndim - 1))


def shape_failed(n: int, k: int) -> str:
    """Why ``n`` numbers make no (k, k) matrix gain."""
    return f"the shape check failed: {n} numbers are neither 1, {k} (a diagonal) nor {k * k} (a {k} × {k} matrix, row by row)"
