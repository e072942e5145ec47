"""Corpus cases of issue 48 (a new user and the fifth hostile run): what the documented
workflow lost, and the classes that run found or left open. Same form and classes as
``cases.py`` (its docstring); ``tests/test_corpus.py`` runs them. Each failed on 0ee2ace.
"""

from __future__ import annotations

from corpus.cases import SIM, C, GiB
from corpus.spec import Case, cli, contains, text

STILL = "times = [0.0, 1.0, 2.0, 3.0]\njoints = [[0.0, 0.3], [0.8, 0.3], [-0.5, 0.3], [0.0, 0.3]]\n"
"""A reference whose joint 2 never moves."""
BASE = ("link1.Izz + 0.1444 link2.m", "link2.mcx", "link2.mcy", "link2.Izz")
"""The twolink's base parameters (``info --json``)."""


def parameter_file(estimate: float) -> str:
    """A parameter file of the twolink whose every base parameter is ``estimate``."""
    import json

    rows = [{"name": name, "estimate": estimate, "std": 0.1} for name in BASE]
    return json.dumps(
        {
            "format": "twolink-pin identified parameters",
            "version": 1,
            "robot": "twolink",
            "nv": 2,
            "parameters": rows,
        }
    )


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
    C("hang-simulate-mpc-horizon-that-fits-under-address-limit", "simulate mpc --duration 0.002 --gain horizon=0.12 --gain knot_interval=0.001", (0, 1), run="proc", memory=3 * GiB // 2, timeout=60, note="120 knots fit: the run goes (or its replan fails with a message), never an abort. The twolink's 22 rows a knot (2 effort, 5 per interval for each of its 4 position and velocity limits) make horizon_bytes 47 584 K² B: 685 MB for 120 knots, under the ~1290 MB a 1.5-GiB process has left (300 knots, 4283 MB, are refused now: their real peak, 2151 MB of address space, would not fit either); measured peak 656 MB of address space (VmPeak; 398 MB at 10 knots), so the estimate errs ~2.6x on the safe side"),
    # == files: --plot DIR holds a file of the user's; one command's outputs all or nothing ===========
    C("dataloss-simulate-plot-over-a-users-file", f"simulate pd {SIM} --plot figs", 2, err=("pd_torque.png", "not a figure twolink-pin wrote"), setup=(text("figs/pd_torque.png", "my own figure"),), absent=("figs/pd_theta1.png",), note="a figure's name in a folder of the user's: refused before anything is moved (no figure of this run is left either)"),
    C("dataloss-trajectory-plot-over-a-users-file", "trajectory --plot figs", 2, err=("trajectory_workspace.png", "not a figure twolink-pin wrote"), setup=(text("figs/trajectory_workspace.png", "mine"), text("figs/notes.txt", "mine")), absent=("figs/trajectory_theta1.png",)),
    C("unclear-simulate-plot-again-replaces-its-own-figures", f"simulate pd {SIM} --plot figs", 0, setup=(cli("simulate", "pd", *SIM.split(), "--plot", "figs"),), changed=("figs",), note="the figures the folder's marker lists are the command's to replace"),
    C("dataloss-simulate-plot-then-save-fails", f"simulate pd {SIM} --plot figs --save blocker/run.npz", 2, err=("blocker", "not a directory"), setup=(text("blocker", "a file"),), absent=("figs",), note="one command, all or nothing: the figures were left behind when --save failed"),
    C("dataloss-identify-plot-then-save-fails", "identify --duration 4 --plot figs --save blocker/p.json", 2, err=("blocker", "not a directory"), setup=(text("blocker", "a file"),), absent=("figs",)),
    # == messages: what is wrong, named ============================================================
    C("unclear-identify-a-joint-never-moves", "identify --trajectory still.toml --duration 6", 2, err=("joint 2 (joint2)", "never moves", "0.01 rad/s"), not_err=("longer run", "excitation"), setup=(text("still.toml", STILL),), note="it spoke of 'the excitation' and advised a longer log; a longer log of a still joint is no better"),
    C("nonfinite-simulate-model-parameter-file-1e300", "simulate computed-torque --duration 0.2 --model p.json", 2, err=("p.json", "link1.Izz + 0.1444 link2.m", "1e+300", "1e+09"), setup=(text("p.json", parameter_file(1e300)),), note="was 'physical fit = unbounded … Clarabel', the file and the values not named"),
    C("nonfinite-simulate-p0-parameter-file-1e12", "simulate adaptive --duration 0.2 --p0 p.json", 2, err=("p.json", "1e+12", "1e+09"), setup=(text("p.json", parameter_file(1e12)),), note="was 'physical fit = infeasible'"),
    # == messages: the runs a sweep counts as diverged say why, in its files =========================
    C("unclear-sweep-mpc-runs-it-could-not-plan-say-why", "sweep mpc --samples 4 --chunk 2 --duration 0.05 --q0-offset 3.5 0 --q0-spread 1 --gain on_infeasible=fail --no-plot --out s", 0, exists=("s/runs.csv",), checks=(contains("s/runs.csv", "diverged_reason"), contains("s/runs.csv", "cannot all hold"), contains("s/runs.json", "position range")), note="runs that start beyond joint 1's range cannot plan: counted as diverged, their reason in runs.csv, runs.json and the Parquet files"),
    C("dataloss-examples-copy-over-a-users-file", "examples --copy ex", 2, err=("ur5_square.toml", "differs from the shipped example"), setup=(text("ex/ur5_square.toml", "my own square"),), absent=("ex/sliding_mode.py",), note="a file of the folder that differs is the user's: refused, and none of the others is written (all or nothing)"),
    C("unclear-examples-copy-twice", "examples --copy ex", 0, setup=(cli("examples", "--copy", "ex"),), out=("already there, identical",), note="copying again over identical files is not an error"),
    # == user code: a hook besides compute ===========================================================
    C("usercode-simulate-law-period-hook-raises", f"simulate {R5}:PeriodRaises {SIM}", 2, err=("corpus-period-raises", "RuntimeError", "period hook failed", "round5.py:"), not_err=("internal error",), note="the hook is asked while the law is built (user code contained): the law, its file and line named"),
    C("usercode-compare-law-period-hook-raises", f"compare {R5}:PeriodRaises pd {SIM} --no-plot --out c", 2, err=("corpus-period-raises", "period hook failed"), not_err=("internal error",), absent=("c",)),
    C("usercode-sweep-law-period-hook-raises", f"sweep {R5}:PeriodRaises --samples 2 {SIM} --no-plot --out s", 2, err=("corpus-period-raises", "period hook failed"), not_err=("internal error",), absent=("s",)),
    # == user code: the process ended, the alarm ignored ==============================================
    C("usercode-simulate-law-os-exit-0", f"simulate {R5}:ExitsHard {SIM} --save run.npz", 1, err=("corpus-exits-hard", "os._exit(0)", "t ="), absent=("run.npz",), note="os._exit(0) ended the process with status 0, a silent success; contained while a command runs"),
    C("usercode-simulate-law-os-exit-0-proc", f"simulate {R5}:ExitsHard {SIM} --save run.npz", 1, err=("corpus-exits-hard", "os._exit(0)"), run="proc", absent=("run.npz",)),
    C("usercode-sweep-law-os-exit-0", f"sweep {R5}:ExitsHard --samples 4 {SIM} --no-plot --out s", 1, err=("corpus-exits-hard", "os._exit(0)"), run="proc", absent=("s",), note="it left the sweep's staging folder behind"),
    C("usercode-report-law-os-exit-0-in-a-worker", f"report --duration 1 --workers 2 --no-animation --no-limits-section --controller {R5}:ExitsHard --controller pd --out r", 1, err=("corpus-exits-hard", "os._exit(0)", "the report with the others"), run="proc", exists=("r/index.html",), timeout=120, note="in a report worker it broke the pool: 'internal error: BrokenProcessPool'"),
    C("usercode-simulate-law-ignores-the-alarm", f"simulate {R5}:IgnoresAlarm {SIM} --timeout 2 --save run.npz", 1, err=("corpus-ignores-alarm", "--timeout 2 s", "SIGALRM"), run="proc", absent=("run.npz",), timeout=40, note="the alarm that ends it ignored: the backstop thread ends the process BACKSTOP_GRACE (10 s) past the bound, naming the law"),
    C("usercode-sweep-law-blocks-the-alarm", f"sweep {R5}:BlocksAlarm --samples 2 {SIM} --timeout 2 --no-plot --out s", 1, err=("corpus-blocks-alarm", "--timeout 2 s", "SIGALRM"), run="proc", absent=("s",), timeout=40, note="and the sweep's staging folder removed"),
]
# fmt: on
