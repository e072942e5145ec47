"""Corpus cases of issue 36's trajectories within limits: ``trajectory --time-optimal`` and
``optimize`` on bad input (one line naming the joint and the limit, exit 2), a solver that does
not converge (exit 1, nothing written, a user's file kept), Ctrl-C while they run.

Kept apart from ``cases.py`` (same form, same ids' classes); ``tests/test_corpus.py`` runs them.
"""

from __future__ import annotations

import json

from corpus.cases import C, via
from corpus.spec import SIGINT, SIGTERM, Case, LibCase, cli, text, twolink

LIMIT = ('effort="240" velocity="10"',)
"""The first joint's <limit> attributes in the shipped twolink.urdf."""
OUTSIDE = '{"times": [0, 1, 2], "joints": [[0, 0], [3.5, 0.3], [0, 0]]}\n'
"""A via point beyond joint 1's range [-3.14159, 3.14159] rad."""
TOO_FAST = '{"times": [0, 0.01, 0.02], "joints": [[0, 0], [1.5, 0.3], [0, 0]]}\n'
"""Via points 10 ms apart, 1.5 rad away: no spline within 10 rad/s can pass them."""
MANY = json.dumps(
    {
        "times": [round(0.01 * k, 2) for k in range(40_000)],
        "joints": [[0.1, 0.2] if k % 4 < 2 else [0.0, 0.2] for k in range(39_999)] + [[0.1, 0.2]],
    }
)
"""A joint trajectory file with 40 000 via points (at most 24 are read)."""
EFFORTS = ('effort="40" velocity="10"',)
"""The second joint's <limit> attributes in the shipped twolink.urdf."""
POSES = "{corpus}/../../examples/ur5_square_pose.toml"
"""The UR5's four via poses (a run of a few seconds: long enough to be interrupted)."""

# fmt: off
OPTIMAL: list[Case] = [
    # --limit-scale outside (0, 1], or without --time-optimal
    C("unclear-trajectory-limit-scale-zero", "trajectory --time-optimal --limit-scale 0", 2, err=("--limit-scale", "0")),
    C("unclear-trajectory-limit-scale-above-one", "trajectory --time-optimal --limit-scale 1.5", 2, err=("--limit-scale", "1.5")),
    C("nonfinite-trajectory-limit-scale-nan", "trajectory --time-optimal --limit-scale nan", 2, err=("--limit-scale", "nan")),
    C("wrong-trajectory-limit-scale-without-time-optimal", "trajectory --limit-scale 0.5", 2, err=("--limit-scale", "--time-optimal"), note="a scale that would change nothing is refused, not ignored"),
    C("wrong-trajectory-friction-without-time-optimal", "trajectory --friction", 2, err=("--friction", "--time-optimal")),
    # a URDF without velocity limits asked to respect them; zero, negative and NaN limits
    C("unclear-trajectory-time-optimal-no-velocity-limits", "trajectory --time-optimal --robot double_pendulum", 2, err=("velocity limit", "joint1")),
    C("unclear-optimize-time-no-velocity-limits", "optimize --cost time --robot double_pendulum", 2, err=("velocity limit", "joint1")),
    C("unclear-trajectory-time-optimal-velocity-zero", "trajectory --time-optimal --robot v.urdf", 2, err=("velocity limit", "joint1"), setup=(twolink("v.urdf", (LIMIT[0], 'effort="240" velocity="0"')),), note="a URDF's 0 means no limit: nothing bounds the duration"),
    C("unclear-trajectory-time-optimal-velocity-negative", "trajectory --time-optimal --robot v.urdf", 2, err=("joint1", "velocity", "-1"), setup=(twolink("v.urdf", (LIMIT[0], 'effort="240" velocity="-1"')),)),
    C("nonfinite-trajectory-time-optimal-velocity-nan", "trajectory --time-optimal --robot v.urdf", 2, err=("joint1", "velocity", "nan"), setup=(twolink("v.urdf", (LIMIT[0], 'effort="240" velocity="nan"')),)),
    C("nonfinite-optimize-effort-nan", "optimize --robot v.urdf", 2, err=("joint1", "effort", "nan"), setup=(twolink("v.urdf", (LIMIT[0], 'effort="nan" velocity="10"')),)),
    # via points outside the position range; more torque than the limits allow even at rest
    C("unclear-optimize-via-outside-range", "optimize --trajectory via.json", 2, err=("via.json", "joint 1", "3.14159"), setup=(via("via.json", OUTSIDE),)),
    C("unclear-trajectory-time-optimal-via-outside-range", "trajectory --time-optimal --trajectory via.json", 2, err=("via.json", "joint 1", "3.14159"), setup=(via("via.json", OUTSIDE),)),
    C("unclear-optimize-gravity-beyond-effort", "optimize --robot ur5 --payload 10000", 2, err=("effort limit of joint", "even at rest"), note="10 t at the tool: gravity alone at the first via point exceeds an effort limit"),
    C("unclear-trajectory-time-optimal-gravity-beyond-effort", "trajectory --time-optimal --robot ur5 --payload 10000", 2, err=("effort limit of joint", "even at rest")),
    C("unclear-optimize-no-via-points", "optimize --trajectory f.toml", 2, err=("via points",), setup=(text("f.toml", "[fourier]\nperiod = 4.0\nharmonics = 1\na = [[0.1], [0.1]]\nb = [[0.0], [0.0]]\noffset = [0.0, 0.5]\n"),)),
    C("unclear-optimize-save-suffix", "optimize --save out.txt", 2, err=("--save", ".json", ".toml"), absent=("out.txt",)),
    # a solver that does not converge, constraints that cannot hold: exit 1, nothing written or replaced
    C("wrong-optimize-not-converged", "optimize --max-iterations 1 --save out.json", 1, err=("the cost did not settle in 1 SQP iterations", "the constraints hold", "try more iterations (--max-iterations"), absent=("out.json",)),
    C("dataloss-optimize-not-converged-keeps-file", "optimize --max-iterations 1 --save mine.json", 1, err=("did not settle",), setup=(text("mine.json", '{"mine": true}\n'),), note="mine.json is byte-identical afterwards (every file not in changed is)"),
    C("unclear-optimize-via-too-fast", "optimize --trajectory via.json --save out.json", 2, err=("velocity limit of joint 1", "10 rad/s", "via point 0 to 1"), setup=(via("via.json", TOO_FAST),), absent=("out.json",), note="via points further apart than a joint can go between their times: refused before solving"),
    # Ctrl-C and SIGTERM while the optimiser runs: 130 / 143, no file
    C("interrupt-optimize-sigint", f"optimize --robot ur5 --trajectory {POSES} --cost time --save out.json", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("out.json",)),
    C("interrupt-optimize-sigterm", f"optimize --robot ur5 --trajectory {POSES} --cost time --save out.json", 143, err=("terminated",), run="signal", signal=(SIGTERM, "running", "parent"), absent=("out.json",)),
    # issue 48's fifth hostile run: limits of 1e-300 and 1e300, long files, a samples file plotted
    C("unclear-trajectory-time-optimal-limit-scale-tiny", "trajectory --time-optimal --limit-scale 1e-300", 2, err=("velocity limit of joint 2", "1e-299 rad/s", "shorter than 1e+06 s"), not_err=("warning", "TOPP-RA"), note="it printed numpy's warnings, then blamed the path (TOPP-RA found no admissible timing)"),
    C("unclear-optimize-time-limit-scale-tiny", "optimize --cost time --limit-scale 1e-300", 2, err=("velocity limit of joint 2", "1e-299 rad/s"), not_err=("warning", "TOPP-RA")),
    C("unclear-optimize-effort-limit-tiny", "optimize --robot e.urdf", 2, err=("effort limit of joint 2", "1e-300 N·m", "the reference needs at its own timing"), setup=(twolink("e.urdf", (EFFORTS[0], 'effort="1e-300" velocity="10"')),), note="it failed with 'the equality constraints cannot all hold (row 12 …)'"),
    C("unclear-trajectory-time-optimal-effort-limit-tiny", "trajectory --time-optimal --robot e.urdf", 2, err=("effort limit of joint 2", "1e-300 N·m"), setup=(twolink("e.urdf", (EFFORTS[0], 'effort="1e-300" velocity="10"')),)),
    C("wrong-trajectory-effort-limit-huge-peak", "trajectory --robot e.urdf", 0, out=("(9.01, 0.75) N·m at t = (1.434, 1.527) s",), setup=(twolink("e.urdf", (LIMIT[0], 'effort="1e300" velocity="10"'), (EFFORTS[0], 'effort="1e300" velocity="10"')),), note="the peaks of the same URDF with its own limits (240, 40 N·m); beside a 1e300 limit |τ| − limit is −1e300 at every instant: the 'peak' was the first sample, 0 at t = 0"),
    C("unclear-trajectory-file-40000-via-points", "trajectory --trajectory many.json", 2, err=("many.json: times", "40000 items", "2 to 24 times"), not_err=("399.98", "0.03,"), setup=(text("many.json", MANY),), note="the error printed the 40 000 times (cut in the middle)"),
    C("traceback-trajectory-samples-file-plot", "trajectory --trajectory r.json --plot figs", 0, out=("figure figs/trajectory_torque.png",), setup=(cli("trajectory", "--time-optimal", "--save", "r.json"),), exists=("figs/trajectory_velocity.png", "figs/trajectory_torque.png"), changed=("figs",), note="a samples file (the retiming --save writes) has no via points: 'internal error: AttributeError … via_q'; its figures are its limits'"),
    C("interrupt-trajectory-time-optimal-sigint", "trajectory --time-optimal --robot panda --save out.json", (0, 130), run="signal", signal=(SIGINT, "running", "group"), absent=(), note="the retiming may finish first: its answer or 130, never a traceback or a partial file"),
]

OPTIMAL_LIBRARY: list[LibCase] = [
    LibCase("library-time_optimal-robot-string", "tp.time_optimal('twolink', trajectory)", ("robot", "RobotModel")),
    LibCase("library-time_optimal-scale-nan", "tp.time_optimal(robot, trajectory, limit_scale=float('nan'))", ("limit scale", "0 < F <= 1")),
    LibCase("library-optimize-cost", "tp.optimize(robot, trajectory, 'speed')", ("cost", "effort, time")),
    LibCase("library-optimize-via-none", "tp.optimize(robot, None)", ("via", "Trajectory")),
    LibCase("library-optimize-ends", "tp.optimize(robot, trajectory, ends='free')", ("ends", "smooth, rest")),
    LibCase("library-optimize-regulariser", "tp.optimize(robot, trajectory, regulariser='jerk')", ("regulariser", "velocity, none")),
    LibCase("library-optimize-regulariser-weight", "tp.optimize(robot, trajectory, regulariser_weight=float('nan'))", ("regulariser weight", "finite")),
    LibCase("library-sampled-nan", "tp.SampledTrajectory(np.array([0.0, 1.0]), np.array([[0.0], [np.nan]]), np.zeros((2, 1)), np.zeros((2, 1)))", ("q[1]", "finite")),
]
# fmt: on
