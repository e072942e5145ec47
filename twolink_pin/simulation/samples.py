"""What the engine writes: blocks of samples (:class:`Samples`), who receives them
(:class:`Observer`) and the buffers they are written into (:class:`Outputs`)."""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np


class Samples(NamedTuple):
    """A block of consecutive output samples of N runs (B samples)."""

    start: int
    """Index of the first sample (sample k is at ``t = k dt``)."""
    t: np.ndarray
    """Times [s], shape (B,)."""
    q: np.ndarray
    """Joint positions [rad], shape (B, N, nv)."""
    v: np.ndarray
    """Joint velocities [rad/s], shape (B, N, nv)."""
    z: np.ndarray
    """The law's state, shape (B, N, nz)."""
    tau_command: np.ndarray
    """Commanded torque [N·m], shape (B, N, nv) (the law's output at the sample)."""
    q_des: np.ndarray
    """Reference positions [rad], shape (B, 1, nv)."""
    v_des: np.ndarray
    """Reference velocities [rad/s], shape (B, 1, nv)."""
    a_des: np.ndarray
    """Reference accelerations [rad/s²], shape (B, 1, nv)."""
    q_measured: np.ndarray | None = None
    """The positions the law measured [rad] (``q`` + sensor noise), shape (B, N, nv); None
    without sensor noise (the law measures ``q``) or outside the full record."""
    v_measured: np.ndarray | None = None
    """The velocities the law measured [rad/s], as ``q_measured``."""
    wrench: np.ndarray | None = None
    """The contact wrench the end effector applies to the surfaces [N; N·m], world axes, about
    its frame's origin, shape (B, N, 6) (the plant's, without sensor noise); None without a
    scene (:class:`~twolink_pin.contact.ContactForces`)."""
    penetration: np.ndarray | None = None
    """The deepest penetration into a surface [m], shape (B, N) (0 out of contact); None
    without a scene."""
    wrench_measured: np.ndarray | None = None
    """The wrench the law's force sensor read (``wrench`` + its noise), as ``wrench``; None
    without force noise or outside the full record."""


class Observer(Protocol):
    """Receives every block of samples as the engine writes it."""

    def add(self, samples: Samples) -> None: ...


class Outputs(NamedTuple):
    """The buffers samples are written into: every sample (``record``) or one block's.
    Shapes (S, N, ·), the reference's (S, 1, nv); ``MQ``, ``MV`` (what the law measured)
    only when the full record is kept under sensor noise; ``W``, ``P`` (the contact's wrench
    and penetration) only with a scene, ``MW`` (the wrench measured) with force noise too."""

    Q: np.ndarray
    V: np.ndarray
    T: np.ndarray
    Z: np.ndarray
    RQ: np.ndarray
    RV: np.ndarray
    RA: np.ndarray
    MQ: np.ndarray | None
    MV: np.ndarray | None
    W: np.ndarray | None = None
    P: np.ndarray | None = None
    MW: np.ndarray | None = None

    @classmethod
    def empty(
        cls, size: int, runs: int, nv: int, nz: int, measured: bool, contact: bool = False, felt: bool = False
    ) -> Outputs:
        """Uninitialised buffers of ``size`` samples (``contact``: with the contact's;
        ``felt``: with the measured wrench)."""
        Q, V, T = (np.empty((size, runs, nv)) for _ in range(3))
        Z = np.empty((size, runs, nz))
        RQ, RV, RA = (np.empty((size, 1, nv)) for _ in range(3))
        MQ, MV = (np.empty((size, runs, nv)) for _ in range(2)) if measured else (None, None)
        W, P = (np.empty((size, runs, 6)), np.empty((size, runs))) if contact else (None, None)
        MW = np.empty((size, runs, 6)) if felt else None
        return cls(Q, V, T, Z, RQ, RV, RA, MQ, MV, W, P, MW)

    def reference(self, rows: slice, rq: np.ndarray, rv: np.ndarray, ra: np.ndarray) -> None:
        """Write the block's reference (its half-step rows ``rq``, ``rv``, ``ra``) at its samples."""
        count = rows.stop - rows.start
        self.RQ[rows], self.RV[rows], self.RA[rows] = (x[: 2 * count : 2] for x in (rq, rv, ra))

    def block(self, start: int, t: np.ndarray, rows: slice) -> Samples:
        """The samples of buffer ``rows`` (the first is sample ``start``, at times ``t``)."""
        Q, V, Z, T, RQ, RV, RA, W, P = (
            self.Q,
            self.V,
            self.Z,
            self.T,
            self.RQ,
            self.RV,
            self.RA,
            self.W,
            self.P,
        )
        contact = (None, None, None, None) if W is None or P is None else (None, None, W[rows], P[rows])
        return Samples(start, t, Q[rows], V[rows], Z[rows], T[rows], RQ[rows], RV[rows], RA[rows], *contact)

    def everything(self, times: np.ndarray) -> Samples:
        """The full record (``record=True``)."""
        return Samples(
            0, times, self.Q, self.V, self.Z, self.T, self.RQ, self.RV, self.RA, self.MQ, self.MV,
            self.W, self.P, self.MW,
        )  # fmt: skip


__all__ = ["Observer", "Outputs", "Samples"]
