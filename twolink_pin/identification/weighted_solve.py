"""The weighted least-squares solve of a stacked observation ``W θ = τ`` and its covariance
(steps 4–6 of :mod:`~twolink_pin.identification.least_squares`, which builds ``W`` and reads
what this returns).

* ordinary least squares; the residual of each joint's rows gives its error variance
  ``σ_j² = ‖ρ_j‖² / (K (1 − n_θ / (K n)))`` (K samples, n joints);
* **weighted** least squares with each joint's rows divided by ``σ_j`` (Gautier 1997,
  "Dynamic identification of robots with power model"; Gautier & Poignet 2001), ``σ_j``
  re-estimated from the weighted residual, :data:`REWEIGHTINGS` solves in all;
* instrumental variables instead of least squares when noise-free instruments are given;
* the sandwich covariance ``B⁻¹ S B⁻ᵀ`` with a Parzen lag window over the score products.
"""

from __future__ import annotations

import numpy as np

REWEIGHTINGS = 3
"""Weighted solves: the joint variances from each solve's residual weight the next (the
ordinary solve's residual mixes the joints' errors through its estimate)."""
SIGMA_FLOOR = 1e-12
"""Smallest joint error standard deviation used as a weight, relative to the torque scale
(noise-free data have residuals at rounding level)."""


def parzen(x: float) -> float:
    """The Parzen lag window on ``x = lag / (bandwidth + 1)`` in [0, 1] (its Fourier transform is
    non-negative: the covariance stays positive semi-definite)."""
    if x <= 0.5:
        return 1.0 - 6.0 * x * x + 6.0 * x**3
    return 2.0 * (1.0 - x) ** 3 if x < 1.0 else 0.0


def joint_weights(residual: np.ndarray, parameters: int, scale: np.ndarray) -> np.ndarray:
    """``σ_j`` per joint from an OLS residual of shape (K, n): ``‖ρ_j‖² / (K (1 − n_θ / (K n)))``,
    floored at :data:`SIGMA_FLOOR` × ``scale`` (the torque scale per joint)."""
    K, n = residual.shape
    dof = max(K * (1.0 - parameters / (K * n)), 1.0)
    sigma = np.sqrt(np.sum(residual**2, axis=0) / dof)
    return np.maximum(sigma, SIGMA_FLOOR * np.maximum(scale, 1e-300))


def solve(
    W: np.ndarray,
    y: np.ndarray,
    weighted: bool = True,
    index: np.ndarray | None = None,
    lags: int = 0,
    instruments: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least squares (or instrumental variables) on ``W`` (K, n, n_θ) and ``y`` (K, n):
    ``(θ̂, Σ_θ, σ_j)``.

    OLS first; with ``weighted`` each joint's rows are then divided by its ``σ_j`` and solved
    again, :data:`REWEIGHTINGS` times, ``σ_j`` re-estimated from each weighted residual (see
    the module docstring). With ``instruments`` ``Z`` (shape of ``W``: the regressor at the
    reference motion, free of measurement noise), each solve is ``θ = (Z_wᵀ W_w)⁻¹ Z_wᵀ y_w``
    instead: consistent when the measured ``W`` is noisy (errors in variables), where least
    squares is biased. The covariance is the sandwich ``B⁻¹ S B⁻ᵀ``, ``B = Z_wᵀ W_w``
    (``Z = W`` for least squares), with ``S`` the lag-window (Parzen-weighted) sum of the
    score products ``g_k g_{k−l}ᵀ`` (``g_k = Z_w,kᵀ ρ_w,k``) of samples ``l <= lags`` apart in
    ``index`` (the samples' positions in the log): errors that the filter made correlated
    over neighbouring samples are counted, gaps in the samples are not bridged. With
    ``lags = 0`` and no instruments it is ``s² B⁻¹``, ``s² = ‖ρ_w‖² / (K n − n_θ)``
    (independent rows).
    """
    K, n, p = W.shape
    Z = W if instruments is None else instruments
    A, b = W.reshape(K * n, p), y.reshape(K * n)
    scale = np.sqrt(np.mean(y**2, axis=0))
    Az = Z.reshape(K * n, p)
    theta = (
        np.linalg.lstsq(A, b, rcond=None)[0] if instruments is None else np.linalg.solve(Az.T @ A, Az.T @ b)
    )
    sigma = joint_weights((b - A @ theta).reshape(K, n), p, scale)
    for _ in range(REWEIGHTINGS if weighted else 1):
        w = 1.0 / sigma if weighted else np.ones(n)
        Ww = W * w[None, :, None]
        Zw = Z * w[None, :, None]
        Aw, Azw = Ww.reshape(K * n, p), Zw.reshape(K * n, p)
        bw = (y * w[None, :]).reshape(K * n)
        B = Azw.T @ Aw
        theta = np.linalg.solve(B, Azw.T @ bw)
        rho = (bw - Aw @ theta).reshape(K, n)
        if weighted:
            sigma = joint_weights(rho / w[None, :], p, scale)
    inverse = np.linalg.inv(B)
    if lags <= 0 and instruments is None:
        s2 = float(np.sum(rho**2)) / max(K * n - p, 1)
        return theta, inverse * s2, sigma
    scores = np.einsum("knp,kn->kp", Zw, rho)
    position = np.arange(K) if index is None else np.asarray(index)
    step = int(np.min(np.diff(position))) if K > 1 else 1
    middle = scores.T @ scores
    for lag in range(1, min(lags, K - 1) + 1):
        paired = position[lag:] - position[:-lag] == lag * step
        if not paired.any():
            continue
        gamma = scores[lag:][paired].T @ scores[:-lag][paired]
        middle += parzen(lag / (lags + 1)) * (gamma + gamma.T)
    dof = K * n / max(K * n - p, 1)
    covariance = inverse @ middle @ inverse.T * dof
    return theta, 0.5 * (covariance + covariance.T), sigma


__all__ = ["REWEIGHTINGS", "SIGMA_FLOOR", "joint_weights", "parzen", "solve"]
