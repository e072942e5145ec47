"""Corpus cases of issue 48 (a new user and the fifth hostile run): what the documented
workflow lost, and the classes that run found or left open. Same form and classes as
``cases.py`` (its docstring); ``tests/test_corpus.py`` runs them. Each failed on 0ee2ace.
"""

from __future__ import annotations

from corpus.cases import SIM, C, GiB
from corpus.spec import Case, cli

R5 = "{corpus}/laws/round5.py"
"""The laws of this round (``laws/round5.py``)."""
NOISY_FIT = cli(
    "identify", "--noise-q", "1e-4", "--noise-tau", "0.5", "--duration", "12", "--write-urdf", "id.urdf"
)
"""A URDF written by ``identify`` from noisy data (it carries no σ)."""

# fmt: off
ROUND5: list[Case] = [
    # == what the documented workflow lost =========================================================
    C("wrong-simulate-model-urdf-of-a-noisy-fit", f"simulate computed-torque {SIM} --model id.urdf", 0, setup=(NOISY_FIT,), note="a URDF carries no σ: its part outside the map (link2.mcy, 0.03 % of the torques) is noise by its torques alone; it was '… 8.9e+299 σ from 0', a σ of 0 taken as 1e-300"),
    C("wrong-compare-model-urdf-of-a-noisy-fit", f"compare computed-torque computed-torque@model=id.urdf {SIM} --no-plot --out c", 0, setup=(NOISY_FIT,), exists=("c/comparison.csv",)),
    # == a memory-starved solver: refused before it is made, against what is left under the limit ===
    C("hang-simulate-mpc-long-horizon-under-address-limit", "simulate mpc --duration 0.002 --gain horizon=0.9 --gain knot_interval=0.001", 2, err=("horizon", "900 knots", "fit in memory", "MB available"), run="proc", memory=3 * GiB // 2, timeout=60, note="ulimit -v 1.5 GiB: ProxQP's factor of 900 knots needs about 2 GB; the check compared its 0.9 GB estimate with the whole limit, not with what the process had left, and the solver aborted (SIGABRT)"),
    C("hang-simulate-mpc-horizon-that-fits-under-address-limit", "simulate mpc --duration 0.002 --gain horizon=0.3 --gain knot_interval=0.001", (0, 1), run="proc", memory=3 * GiB // 2, timeout=60, note="300 knots fit: the run goes (or its replan fails with a message), never an abort"),
    # == user code: a hook besides compute ===========================================================
    C("usercode-simulate-law-period-hook-raises", f"simulate {R5}:PeriodRaises {SIM}", 2, err=("corpus-period-raises", "RuntimeError", "period hook failed", "round5.py:"), not_err=("internal error",), note="the hook is asked while the law is built (user code contained): the law, its file and line named"),
    C("usercode-compare-law-period-hook-raises", f"compare {R5}:PeriodRaises pd {SIM} --no-plot --out c", 2, err=("corpus-period-raises", "period hook failed"), not_err=("internal error",), absent=("c",)),
    C("usercode-sweep-law-period-hook-raises", f"sweep {R5}:PeriodRaises --samples 2 {SIM} --no-plot --out s", 2, err=("corpus-period-raises", "period hook failed"), not_err=("internal error",), absent=("s",)),
]
# fmt: on
