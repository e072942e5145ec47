"""The derivation itself: from a :class:`~twolink_pin.symbolic.skeleton.Skeleton` to the terms
of the dynamics in the base parameters, as exact polynomials (what the cache stores).

Steps: the standard terms ``M^{(π)}``, ``g^{(π)}`` of every inertial parameter
(:mod:`~twolink_pin.symbolic.lagrange`); the base parameters
(:mod:`~twolink_pin.symbolic.grouping`); for each kept parameter k, ``C^{(k)}`` by the
Christoffel symbols and the check that ``Ṁ^{(k)} − 2 C^{(k)}`` is skew-symmetric (exactly:
the dynamics being linear in the parameters, it then holds for every β). Then

    M(q) = Σ_k β_k M^{(k)}(q),   C(q, q̇) = Σ_k β_k C^{(k)}(q, q̇),   g(q) = Σ_k β_k g^{(k)}(q),

and the regressor's column k is ``M^{(k)} q̈ + C^{(k)}(q, q̇) w + g^{(k)}`` (``w = q̇``: the
inverse dynamics; ``w = q̇_r``: the Slotine–Li form).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from twolink_pin.symbolic.grouping import Grouping, group
from twolink_pin.symbolic.kinematics import Matrix, Vector
from twolink_pin.symbolic.lagrange import christoffel, regressor_column, skew_defect, standard_terms
from twolink_pin.symbolic.skeleton import Skeleton
from twolink_pin.symbolic.trig_ring import TILTED_TOLERANCE, TrigRing


@dataclass(frozen=True)
class Derivation:
    """The dynamics of one skeleton in its base parameters, as polynomials of :attr:`ring`."""

    ring: TrigRing
    grouping: Grouping
    masses: tuple[Matrix, ...]
    """``M^{(k)}`` of each base parameter (n × n)."""
    coriolis: tuple[Matrix, ...]
    """``C^{(k)}`` of each base parameter (n × n, linear in ``dq1..dqn``)."""
    gravities: tuple[Vector, ...]
    """``g^{(k)}`` of each base parameter (n)."""
    skew_symmetric: bool
    """Whether ``Ṁ − 2C`` was found skew-symmetric (exactly) for every base parameter."""
    seconds: float
    """Wall-clock time the derivation took [s] (when it was derived, not read from a cache)."""

    def regressor_columns(self) -> list[Vector]:
        """Column k of ``Y(q, q̇, w, q̈)`` for each base parameter."""
        return [
            regressor_column(self.ring, M, C, g)
            for M, C, g in zip(self.masses, self.coriolis, self.gravities)
        ]


def derive(skeleton: Skeleton) -> Derivation:
    """Derive the dynamics of ``skeleton`` (see the module docstring)."""
    start = time.perf_counter()
    ring = TrigRing(skeleton.kinds, list(skeleton.lengths()), TILTED_TOLERANCE if skeleton.tilted else None)
    masses, gravities = standard_terms(ring, skeleton)
    grouping = group(ring, masses, gravities)
    kept_masses = tuple(masses[k] for k in grouping.kept)
    coriolis = tuple(christoffel(ring, M) for M in kept_masses)
    skew = all(skew_defect(ring, M, C) is None for M, C in zip(kept_masses, coriolis))
    return Derivation(
        ring=ring,
        grouping=grouping,
        masses=kept_masses,
        coriolis=coriolis,
        gravities=tuple(gravities[k] for k in grouping.kept),
        skew_symmetric=skew,
        seconds=time.perf_counter() - start,
    )


def to_json(derivation: Derivation) -> dict[str, Any]:
    """A JSON-ready form of ``derivation`` (polynomials as term lists)."""
    ring = derivation.ring
    terms = ring.to_dict
    return {
        "kinds": list(ring.kinds),
        "lengths": list(ring.length_names),
        "tolerance": ring.tolerance,
        "kept": list(derivation.grouping.kept),
        "combination": [
            {str(d): [terms(num), terms(den)] for d, (num, den) in combo.items()}
            for combo in derivation.grouping.combination
        ],
        "masses": [[[terms(x) for x in row] for row in M] for M in derivation.masses],
        "coriolis": [[[terms(x) for x in row] for row in C] for C in derivation.coriolis],
        "gravities": [[terms(x) for x in g] for g in derivation.gravities],
        "skew_symmetric": derivation.skew_symmetric,
        "seconds": derivation.seconds,
    }


def from_json(data: dict[str, Any]) -> Derivation:
    """The inverse of :func:`to_json` (raises ``KeyError``, ``TypeError`` or ``ValueError`` on
    a malformed document)."""
    tolerance = data["tolerance"]
    ring = TrigRing(
        [str(k) for k in data["kinds"]],
        [str(name) for name in data["lengths"]],
        None if tolerance is None else float(tolerance),
    )
    poly = ring.from_dict
    grouping = Grouping(
        kept=tuple(int(k) for k in data["kept"]),
        combination=tuple(
            {int(d): (poly(num), poly(den)) for d, (num, den) in combo.items()}
            for combo in data["combination"]
        ),
    )
    return Derivation(
        ring=ring,
        grouping=grouping,
        masses=tuple([[poly(x) for x in row] for row in M] for M in data["masses"]),
        coriolis=tuple([[poly(x) for x in row] for row in C] for C in data["coriolis"]),
        gravities=tuple([poly(x) for x in g] for g in data["gravities"]),
        skew_symmetric=bool(data["skew_symmetric"]),
        seconds=float(data["seconds"]),
    )
