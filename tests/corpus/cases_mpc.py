"""Corpus cases of issue 37's ``mpc`` law: a horizon of 0, negative, NaN, shorter than a knot
interval or too long for the memory, a replanning period shorter than the step or not a multiple
of it, gains that must be one value drawn per run (exit 2, one line naming the value); a replan
whose limits cannot all hold (exit 1 at its time, the row named) — and ``compare`` still writes
the other laws' results.

Kept apart from ``cases.py`` (same form, same ids' classes); ``tests/test_corpus.py`` runs them.
"""

from __future__ import annotations

from corpus.cases import C
from corpus.spec import Case

SIM = "--duration 0.2"
"""A short run: 20 replans."""
OUTSIDE = "--q0-offset 4 0"
"""Joint 1 starts 0.86 rad beyond its range [-3.14159, 3.14159] rad: no torque within the
limit brings it back by the first knot (25 ms)."""

# fmt: off
MPC: list[Case] = [
    C("unclear-simulate-mpc-horizon-zero", f"simulate mpc {SIM} --gain horizon=0", 2, err=("horizon", "0", "> 0")),
    C("unclear-simulate-mpc-horizon-negative", f"simulate mpc {SIM} --gain horizon=-0.2", 2, err=("horizon", "-0.2", "> 0")),
    C("nonfinite-simulate-mpc-horizon-nan", f"simulate mpc {SIM} --gain horizon=nan", 2, err=("horizon", "nan", "finite")),
    C("nonfinite-simulate-mpc-horizon-inf", f"simulate mpc {SIM} --gain horizon=inf", 2, err=("horizon", "inf")),
    C("unclear-simulate-mpc-horizon-below-knot-interval", f"simulate mpc {SIM} --gain horizon=0.01", 2, err=("horizon", "0.01", "at least one knot interval (0.025 s)")),
    C("hang-simulate-mpc-horizon-too-long-for-memory", f"simulate mpc {SIM} --gain horizon=1000 --gain knot_interval=0.001", 2, err=("horizon", "1000 s (1000000 knots", "fit in memory", "MB available"), note="refused before anything of its size is made: 8 B × (10 (n + m)² + 9 n² + 2 m n + N (5 n² + m n)) against the memory available"),
    C("unclear-simulate-mpc-replan-shorter-than-step", f"simulate mpc {SIM} --gain replan_period=0.0005", 2, err=("mpc: update period", "0.0005", "multiple of the simulation step dt = 0.001 s")),
    C("unclear-simulate-mpc-replan-not-a-multiple", f"simulate mpc {SIM} --gain replan_period=0.0015", 2, err=("mpc: update period", "0.0015", "multiple of the simulation step")),
    C("unclear-simulate-mpc-replan-zero", f"simulate mpc {SIM} --gain replan_period=0", 2, err=("replan_period", "0", "> 0")),
    C("unclear-sweep-mpc-horizon-per-run", "sweep mpc --samples 2 --duration 0.2 --gain horizon=0.1:0.3 --out out", 2, err=("horizon", "one value of horizon for every run"), absent=("out",), note="the horizon shapes every run's QP: a sweep may not draw it per run"),
    C("unclear-simulate-mpc-limit-scale-zero", f"simulate mpc {SIM} --gain limit_scale=0", 2, err=("limit_scale", "0", "fraction")),
    # limits that cannot all hold: exit 1 at once (ProxQP's iterations capped), the row and the time named
    C("wrong-simulate-mpc-infeasible-start", f"simulate mpc {SIM} {OUTSIDE} --gain on_infeasible=fail", 1, err=("'mpc' failed at t = 0 s", "cannot all hold", "position range [-3.14159, 3.14159] rad of joint 1 (joint1) at t + ")),
    C("wrong-simulate-mpc-infeasible-save-nothing", f"simulate mpc {SIM} {OUTSIDE} --gain on_infeasible=fail --save run.npz", 1, err=("failed at t = 0 s",), absent=("run.npz",)),
    C("dataloss-compare-mpc-infeasible-writes-the-others", f"compare pd mpc --robot ur5 {SIM} --gain mpc.limit_scale=0.01 --gain mpc.on_infeasible=fail --no-plot --out out", 1, err=("1 law(s) did not finish", "'mpc' failed at t = 0 s", "cannot all hold", "the other laws' results are in out"), exists=("out/comparison.md", "out/comparison.csv", "out/comparison.json"), note="1 % of the UR5's effort limits cannot hold its arm up: mpc fails at t = 0, pd's run is written and mpc's row says when and why"),
]
