"""Corpus cases of issue 36's trajectories within limits: ``trajectory --time-optimal`` and
``optimize`` on bad input (one line naming the joint and the limit, exit 2), a solver that does
not converge (exit 1, nothing written, a user's file kept), Ctrl-C while they run.

Kept apart from ``cases.py`` (same form, same ids' classes); ``tests/test_corpus.py`` runs them.
"""

from __future__ import annotations

from corpus.cases import C, via
from corpus.spec import SIGINT, SIGTERM, Case, LibCase, text, twolink

LIMIT = ('effort="240" velocity="10"',)
"""The first joint's <limit> attributes in the shipped twolink.urdf."""
OUTSIDE = '{"times": [0, 1, 2], "joints": [[0, 0], [3.5, 0.3], [0, 0]]}\n'
"""A via point beyond joint 1's range [-3.14159, 3.14159] rad."""
TOO_FAST = '{"times": [0, 0.01, 0.02], "joints": [[0, 0], [1.5, 0.3], [0, 0]]}\n'
"""Via points 10 ms apart, 1.5 rad away: no spline within 10 rad/s can pass them."""
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
    C("interrupt-trajectory-time-optimal-sigint", "trajectory --time-optimal --robot panda --save out.json", (0, 130), run="signal", signal=(SIGINT, "running", "group"), absent=(), note="the retiming may finish first: its answer or 130, never a traceback or a partial file"),
]

OPTIMAL_LIBRARY: list[LibCase] = [
    LibCase("library-time_optimal-robot-string", "tp.time_optimal('twolink', trajectory)", ("robot", "RobotModel")),
    LibCase("library-time_optimal-scale-nan", "tp.time_optimal(robot, trajectory, limit_scale=float('nan'))", ("limit scale", "0 < F <= 1")),
    LibCase("library-optimize-cost", "tp.optimize(robot, trajectory, 'speed')", ("cost", "effort, time")),
    LibCase("library-optimize-via-none", "tp.optimize(robot, None)", ("via", "Trajectory")),
    LibCase("library-sampled-nan", "tp.SampledTrajectory(np.array([0.0, 1.0]), np.array([[0.0], [np.nan]]), np.zeros((2, 1)), np.zeros((2, 1)))", ("q[1]", "finite")),
]
# fmt: on
