"""The nearest physically consistent rotational inertia: what ``--repair-inertias`` writes.

A URDF exported from CAD often gives a link an inertia whose principal moments break the
triangle inequality by a percent or so (``I₃ > I₁ + I₂``: no mass distribution has it). A rigid
body with mass ``m > 0`` and centre of mass ``c`` is physically consistent exactly when its
pseudo-inertia is positive semidefinite (Wensing, Kim & Slotine 2017, the LMI
:mod:`twolink_pin.identification.physical` fits with); with ``m`` and ``c`` kept that is
``Σ = ½ tr(I) 𝟙 − I ⪰ 0`` for the inertia ``I`` about the centre of mass — the triangle
inequality on its principal moments (and ``I ⪰ 0``).

That set is a spectral set: convex, and invariant under rotations. The Frobenius-nearest
matrix in such a set keeps the eigenvectors and projects the eigenvalues (Lewis, "Convex
analysis on the Hermitian matrices", SIAM J. Optim. 6(1), 1996): with the moments
``λ₁ ≤ λ₂ ≤ λ₃`` and the excess ``δ = λ₃ − λ₁ − λ₂ > 0``, the projection onto the half-space
``μ₃ ≤ μ₁ + μ₂`` is ``μ = (λ₁ + δ/3, λ₂ + δ/3, λ₃ − δ/3)``, which meets every other inequality
(``μ₁ ≤ μ₂ + μ₃``, ``μ ≥ 0``), so it is the projection onto the whole set: the repaired inertia
``U diag(μ) Uᵀ`` is on the boundary (a flat body), at Frobenius distance ``δ/√3`` [kg·m²] from
the original, with the same principal axes, mass and centre of mass (its trace grows by δ/3). (MuJoCo's
``balanceinertia`` instead sets all three moments to their mean: further from the original,
and the principal axes' moments no longer differ.) This is the identification's LMI projection
restricted to the one block that is broken, in closed form — no solver.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

ATTRIBUTES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
"""The six ``<inertia>`` attributes, in URDF's order."""


class InertiaRepair(NamedTuple):
    """One link's inertia replaced by :func:`nearest_consistent` (about its centre of mass)."""

    link: str
    """The link's name."""
    before: tuple[float, ...]
    """``ixx ixy ixz iyy iyz izz`` as the URDF gives them [kg·m²]."""
    after: tuple[float, ...]
    """The repaired six values [kg·m²]."""
    moments_before: tuple[float, float, float]
    """Principal moments before, ascending [kg·m²]."""
    moments_after: tuple[float, float, float]
    """Principal moments after, ascending [kg·m²] (the largest = the sum of the other two)."""
    change: float
    """``‖I' − I‖_F`` [kg·m²] (``δ/√3``)."""
    relative: float
    """``‖I' − I‖_F / ‖I‖_F``."""

    def describe(self) -> str:
        """One line: the link, the moments before and after, the change in kg·m² and relative."""

        def moments(m: tuple[float, ...]) -> str:
            return "(" + ", ".join(f"{x:.6g}" for x in m) + ")"

        return (
            f"link '{self.link}': principal moments {moments(self.moments_before)} → "
            f"{moments(self.moments_after)} kg·m², inertia changed by {self.change:.3g} kg·m² "
            f"({100 * self.relative:.3g} % of its norm)"
        )


def inertia_matrix(values: tuple[float, ...]) -> np.ndarray:
    """The symmetric 3 × 3 matrix of ``ixx ixy ixz iyy iyz izz`` [kg·m²]."""
    ixx, ixy, ixz, iyy, iyz, izz = values
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def nearest_consistent(link: str, values: tuple[float, ...]) -> InertiaRepair:
    """The Frobenius-nearest inertia to ``values`` (``ixx … izz`` [kg·m²], symmetric, positive
    semidefinite) whose principal moments satisfy the triangle inequality (module docstring)."""
    matrix = inertia_matrix(values)
    lam, U = np.linalg.eigh(matrix)  # ascending
    excess = float(lam[2] - lam[0] - lam[1])
    mu = lam.copy()
    if excess > 0:
        mu += np.array([1.0, 1.0, -1.0]) * excess / 3.0
    repaired = (U * mu) @ U.T
    repaired = 0.5 * (repaired + repaired.T)
    after = tuple(float(repaired[i, j]) for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))
    change = float(np.linalg.norm(repaired - matrix))
    norm = float(np.linalg.norm(matrix))
    return InertiaRepair(
        link,
        tuple(float(x) for x in values),
        after,
        (float(lam[0]), float(lam[1]), float(lam[2])),
        (float(mu[0]), float(mu[1]), float(mu[2])),
        change,
        change / norm if norm > 0 else math.inf,
    )
