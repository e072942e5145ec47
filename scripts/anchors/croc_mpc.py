"""The anchor's side of ``scripts/benchmark.py --mpc-only``: crocoddyl's BoxFDDP MPC on a reference
twolink-pin exported (``scripts/mpc_anchor.py`` writes it), with the toolkit's horizon, knots,
replanning period, weights and limit scale, on the same plant step. Run by the benchmark in a
scratch virtual environment (never a dependency of the project)::

    python3 -m venv /tmp/croc && /tmp/croc/bin/pip install pin==4.0.0 crocoddyl==3.2.1
    CROCODDYL_PYTHON=/tmp/croc/bin/python .venv/bin/python scripts/benchmark.py --mpc-only

(crocoddyl 3.2.1's wheel was built against pin 4.0 and crashes beside pin 4.1 on frame costs.) It
imports nothing of twolink-pin: what it needs comes in ``JOB.json`` and ``JOB.npz``.

    python croc_mpc.py JOB.json     # prints one JSON line

The loop (after ``../shared/bench/optctl/croc_mpc.py``, the peer measured beside ``mpc`` on the
course's polynomial): the URDF's forward dynamics (``pin.aba``, no friction), classical RK4 at
``dt``, the law at every RK4 stage, from the toolkit's initial state. Every ``replan`` seconds, a
shooting problem of ``K = horizon / knot`` Euler nodes ``knot`` apart, cost
``h Σ ‖W_q (q − q_r)‖² + ‖W_v (q̇ − q̇_r)‖² + h w_τ Σ ‖τ − τ_r‖²`` (the toolkit's weights; ``τ_r``
the RNEA of the reference), ``|τ| ≤ f τ_max`` (BoxFDDP's box), the velocity limit (× f) and the
position range as a quadratic barrier (crocoddyl has no hard state bounds), the reference at
each node's time (crocoddyl's usual preview), one FDDP iteration from the previous plan shifted
(20 for the first). Between replans: ``τ = clip(u_k − K_k (x − x_plan(t)), ±τ_max)`` with the
plan's Riccati gains, ``x_plan`` linear between nodes. ``OMP_NUM_THREADS=1``: one thread, as the
toolkit's single run.
"""

import json
import sys
import time
from pathlib import Path

import crocoddyl
import numpy as np
import pinocchio as pin


def main() -> None:
    job = json.loads(Path(sys.argv[1]).read_text())
    arrays = np.load(job["arrays"])
    _ref_t, ref_q, ref_v, ref_a = arrays["t"], arrays["q"], arrays["v"], arrays["a"]
    grid = float(job["grid"])  # the reference's samples are every `grid` seconds from 0

    def reference(t):
        k = np.rint(np.asarray(t) / grid).astype(int)
        return ref_q[k], ref_v[k], ref_a[k]

    model = pin.buildModelFromUrdf(job["urdf"])
    data = model.createData()
    nv = model.nv
    limits = job["limits"]
    eff, vel = np.array(limits["effort"], dtype=float), np.array(limits["velocity"], dtype=float)
    lo, hi = np.array(limits["position_lower"], dtype=float), np.array(limits["position_upper"], dtype=float)
    g = job["gains"]
    h, replan, f, dt = (
        float(g["knot_interval"]),
        float(g["replan_period"]),
        float(g["limit_scale"]),
        float(job["dt"]),
    )
    H = round(float(g["horizon"]) / h)
    wq2, wv2 = (
        np.asarray(g["weight_q"], dtype=float).ravel() ** 2,
        np.asarray(g["weight_v"], dtype=float).ravel() ** 2,
    )
    wt = float(g["weight_tau"])
    state = crocoddyl.StateMultibody(model)
    actuation = crocoddyl.ActuationModelFull(state)

    def node(terminal):
        costs = crocoddyl.CostModelSum(state, nv)
        w = 2 * np.concatenate([wq2, wv2]) * (h if terminal else 1.0)
        residual = crocoddyl.ResidualModelState(state, np.zeros(2 * nv), nv)
        costs.addCost(
            "x", crocoddyl.CostModelResidual(state, crocoddyl.ActivationModelWeightedQuad(w), residual), 1.0
        )
        if not terminal:
            control = crocoddyl.ResidualModelControl(state, np.zeros(nv))
            costs.addCost("u", crocoddyl.CostModelResidual(state, control), 2 * wt)
        bounds = crocoddyl.ActivationBounds(np.concatenate([lo, -f * vel]), np.concatenate([hi, f * vel]))
        barrier = crocoddyl.ActivationModelQuadraticBarrier(bounds)
        state_residual = crocoddyl.ResidualModelState(state, np.zeros(2 * nv), nv)
        costs.addCost("limits", crocoddyl.CostModelResidual(state, barrier, state_residual), 1e4)
        diff = crocoddyl.DifferentialActionModelFreeFwdDynamics(state, actuation, costs)
        action = crocoddyl.IntegratedActionModelEuler(diff, 0.0 if terminal else h)
        if not terminal:
            action.u_lb, action.u_ub = -f * eff, f * eff
        return action

    running = [node(False) for _ in range(H)]
    terminal = node(True)
    rx = [m.differential.costs.costs["x"].cost.residual for m in running]
    rx.append(terminal.differential.costs.costs["x"].cost.residual)
    ru = [m.differential.costs.costs["u"].cost.residual for m in running]
    q0, v0, _ = reference(0.0)
    x = np.concatenate([q0 + np.asarray(job["q0_offset"], dtype=float), v0])
    problem = crocoddyl.ShootingProblem(x.copy(), running, terminal)
    problem.nthreads = 1
    solver = crocoddyl.SolverBoxFDDP(problem)
    nodes = h * np.arange(H + 1)
    plan = {}

    def solve(t, x, iterations, warm):
        q, v, a = reference(t + nodes)
        for i in range(H + 1):
            rx[i].reference = np.concatenate([q[i], v[i]])
        for i in range(H):
            ru[i].reference = pin.rnea(model, data, q[i], v[i], a[i])
        problem.x0 = x
        if warm is None:
            gravity = pin.rnea(model, data, x[:nv], x[nv:], np.zeros(nv))
            xs, us = [x.copy() for _ in range(H + 1)], [gravity.copy() for _ in range(H)]
        else:
            xs_p, us_p, t_p = warm
            s = (t - t_p) + nodes
            k = np.minimum((s / h + 1e-9).astype(int), H - 1)
            us = [us_p[j].copy() for j in k[:H]]
            frac = np.clip(s / h - k, 0.0, 1.0)[:, None]
            states = xs_p[k] + frac * (xs_p[np.minimum(k + 1, H)] - xs_p[k])
            xs = [row.copy() for row in states]
            xs[0] = x.copy()
        solver.solve(xs, us, iterations, False)
        plan.update(t=t, xs=np.array(solver.xs), us=np.array(solver.us), K=np.array(solver.K))

    def law(t, x):
        s = t - plan["t"]
        k = min(int(s / h + 1e-9), H - 1)
        x_plan = plan["xs"][k] + ((s - k * h) / h) * (plan["xs"][k + 1] - plan["xs"][k])
        return np.clip(plan["us"][k] - plan["K"][k] @ (x - x_plan), -eff, eff)

    def rhs(x, u):
        return np.concatenate([x[nv:], pin.aba(model, data, x[:nv], x[nv:], u)])

    n = round(float(job["duration"]) / dt)
    every = round(replan / dt)
    Q, V, U = np.empty((n + 1, nv)), np.empty((n + 1, nv)), np.empty((n + 1, nv))
    replans = []
    wall0 = time.perf_counter()
    for i in range(n):
        t = i * dt
        if i % every == 0:
            start = time.perf_counter()
            if i == 0:
                solve(t, x, 20, None)
            else:
                solve(t, x, 1, (plan["xs"], plan["us"], plan["t"]))
                replans.append(time.perf_counter() - start)
        Q[i], V[i] = x[:nv], x[nv:]
        u1 = law(t, x)
        U[i] = u1
        k1 = rhs(x, u1)
        x2 = x + 0.5 * dt * k1
        k2 = rhs(x2, law(t + 0.5 * dt, x2))
        x3 = x + 0.5 * dt * k2
        k3 = rhs(x3, law(t + 0.5 * dt, x3))
        x4 = x + dt * k3
        k4 = rhs(x4, law(t + dt, x4))
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    Q[n], V[n], U[n] = x[:nv], x[nv:], law(n * dt, x)
    wall = time.perf_counter() - wall0
    times = dt * np.arange(n + 1)
    e = Q - reference(times)[0]
    last = times >= times[-1] - float(job["period"]) - 1e-12
    print(
        json.dumps(
            {
                "wall_s": wall,
                "real_time_factor": float(job["duration"]) / wall,
                "replan_us": 1e6 * float(np.mean(replans)),
                "rms_e": np.sqrt(np.mean(e**2, axis=0)).tolist(),
                "last_period_max_e": np.abs(e[last]).max(axis=0).tolist(),
                "excess": {
                    "effort": float(np.max(np.abs(U) - eff)),
                    "velocity": float(np.max(np.abs(V) - vel)),
                    "position": float(np.max(np.maximum(Q - hi, lo - Q))),
                },
                "crocoddyl": crocoddyl.__version__,
                "pinocchio": pin.__version__,
            }
        )
    )


if __name__ == "__main__":
    main()
