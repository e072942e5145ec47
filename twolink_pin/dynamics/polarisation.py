"""The polarisation pair and forest: the model term ``M a + C(q, v) w + g`` in one RNEA.

By polarisation of the Christoffel form (see :func:`twolink_pin.dynamics.regressor`),
``M(q) a + C(q, v) w + g(q) = RNEA(q, (v+w)/2, a) − RNEA₀(q, (v−w)/2, 0)`` (RNEA₀ without
gravity). A model holding two copies of the arm evaluates both terms in one call.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin


def polarisation_pair(model: pin.Model) -> pin.Model:
    """Two copies of ``model`` side by side, so that one call evaluates the polarisation.

    By polarisation of the Christoffel form (see :func:`regressor`), the model term of
    every law is ``M(q) a + C(q, v) w + g(q) = RNEA(q, (v+w)/2, a) − RNEA₀(q, (v−w)/2, 0)``,
    RNEA₀ without gravity: RNEA (or the regressor) at two inputs, ``A = (q, (v+w)/2, a)``
    with gravity and ``B = (q, (v−w)/2, 0)`` without. Each call from
    Python costs ~0.6 µs of binding overhead, more than RNEA's own work on a small arm, so
    the fast simulator makes one call on a model holding both: copy A (joints ``0..nv−1``)
    and copy B (joints ``nv..2nv−1``), both attached to the universe. Gravity is shared by
    the copies, so the pair has **half** the model's gravity and copy B is mounted upside
    down (turned by π about an axis normal to gravity, which leaves its M and C unchanged
    and reverses the gravity it feels). Then, for ``Q = (q, q)``, ``V = ((v+w)/2, (v−w)/2)``,
    ``A = (a, 0)``::

        τ_A − τ_B = M a + C(q, v) w + g/2 + g/2          (RNEA on the pair)
        Y_A − Y_B = Y_π(q, v, w, a)                      (regressor: diagonal blocks)

    Raises:
        ValueError: ``nq != nv`` (the input layout above needs one coordinate per joint).
    """
    return polarisation_forest([model])


def polarisation_forest(models: Sequence[pin.Model]) -> pin.Model:
    """The :func:`polarisation_pair` of each of ``models``, all in one model: copies
    ``A_0, B_0, A_1, B_1, ...`` (joints ``2 i nv ..`` and ``(2 i + 1) nv ..``).

    The models must share their kinematics and gravity (e.g. differ only in inertias, as
    the batch engine's regressor columns do); the first one's gravity is used.

    Raises:
        ValueError: no model, or ``nq != nv``.
    """
    if not models:
        raise ValueError("expected at least one model, got none")
    first = models[0]
    if first.nq != first.nv:
        raise ValueError(f"expected a model with nq == nv, got nq = {first.nq}, nv = {first.nv}")
    g = np.array(first.gravity.linear, dtype=float)
    axis = np.cross(g, [1.0, 0.0, 0.0])
    if np.linalg.norm(axis) < 1e-9 * max(1.0, float(np.linalg.norm(g))):
        axis = np.cross(g, [0.0, 1.0, 0.0])
    norm = float(np.linalg.norm(axis))
    u = axis / norm if norm > 0 else np.array([1.0, 0.0, 0.0])
    flipped = pin.SE3(2.0 * np.outer(u, u) - np.eye(3), np.zeros(3))  # rotation by π about u
    forest = _renamed(models[0], "0a/")
    for i, model in enumerate(models):
        if i > 0:
            forest = pin.appendModel(forest, _renamed(model, f"{i}a/"), 0, pin.SE3.Identity())
        forest = pin.appendModel(forest, _renamed(model, f"{i}b/"), 0, flipped)
    forest.gravity = pin.Motion(0.5 * first.gravity.vector)
    forest.armature = np.concatenate([m.armature for m in models for _ in range(2)])
    return forest


def _renamed(model: pin.Model, prefix: str) -> pin.Model:
    """A copy of ``model`` with ``prefix`` on every joint and frame name but the universe's
    (a frame whose name another frame has already, as a link and the fixed joint before it
    may, also gets ``#index``: ``appendModel`` looks frames up by name)."""
    copy = pin.Model(model)
    for j in range(1, copy.njoints):
        copy.names[j] = prefix + copy.names[j]
    seen: set[str] = set()
    for i in range(1, len(copy.frames)):
        frame = copy.frames[i]
        name = prefix + frame.name
        frame.name = name if name not in seen else f"{name}#{i}"
        seen.add(frame.name)
        copy.frames[i] = frame
    return copy
