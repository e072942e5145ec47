"""Corpus cases of issue 30's classes: ``--timeout`` exact at every size, stiff adaptive runs
that end fast, the library API's wrong types and NaN results, Dask at the process limit.

Kept apart from ``cases.py`` (same form, same ids' classes) so the lists there stay as they
are; ``tests/test_corpus.py`` runs both.
"""

from __future__ import annotations

from corpus.cases import REP, SIM, C
from corpus.spec import Case, LibCase, text

TIMEOUT = ("did not finish within --timeout", "pd")
"""What every --timeout message says: the bound and the law."""

CANNOT_FORK = """import errno, os, multiprocessing.process
start = multiprocessing.process.BaseProcess.start
def start_at_the_limit(self):  # a Dask worker process: refused as fork is at the process limit
    if "Dask Worker" in self.name:
        raise OSError(errno.EAGAIN, os.strerror(errno.EAGAIN))
    start(self)
multiprocessing.process.BaseProcess.start = start_at_the_limit
"""
"""A ``sitecustomize`` (on ``PYTHONPATH``) that fails every start of a Dask worker process as
fork fails at the limit on processes; tests/test_cluster_limit.py reaches the kernel's limit
itself (a pids cgroup)."""

# fmt: off
LIMITS: list[Case] = [
    # --timeout: a bound so small the alarm fires while it is armed is the same one-line error
    C("traceback-simulate-timeout-1e-9", f"simulate pd {SIM} --timeout 1e-9", 1, err=(*TIMEOUT, "1e-09"), run="proc"),
    C("traceback-simulate-adaptive-timeout-1e-9", f"simulate pd {SIM} --method adaptive --timeout 1e-9", 1, err=(*TIMEOUT, "1e-09"), run="proc"),
    C("traceback-simulate-timeout-1e-6", f"simulate pd {SIM} --timeout 1e-6", 1, err=(*TIMEOUT, "1e-06"), run="proc"),
    C("traceback-compare-timeout-1e-9", f"compare pd computed-torque {SIM} --no-plot --out c --timeout 1e-9", 1, err=(*TIMEOUT, "1e-09", "computed-torque"), run="proc", changed=("c",)),
    C("traceback-sweep-timeout-1e-9", f"sweep pd --samples 2 {SIM} --no-plot --out s --timeout 1e-9", 1, err=(*TIMEOUT, "1e-09"), run="proc", absent=("s/summary.json",)),
    C("traceback-report-timeout-1e-9", f"report {REP} --out r --timeout 1e-9", 1, err=(*TIMEOUT, "1e-09"), run="proc", note="the report keeps the other laws: here none, an index that says so"),
    # stiff: the adaptive step held at a fraction of dt is recognised from its pace, not after its whole budget
    C("hang-simulate-adaptive-lambda-1e5", "simulate computed-torque --method adaptive --lambda 1e5", 1, err=("computed-torque", "t = 0.", "collapsed to about", "steps per dt"), timeout=60, note="73 s of work before the budget ran out; the pace is projected after 20 000 evaluations"),
    # Dask at the process limit: one line naming the reason and what to do, exit 2 as every cluster error
    C("traceback-sweep-dask-workers-cannot-fork", f"sweep pd --samples 4 {SIM} --no-plot --workers 2 --out s", 2, err=("the 2 Dask worker processes could not start", "Resource temporarily unavailable", "fewer workers"), setup=(text("hook/sitecustomize.py", CANNOT_FORK),), env=(("PYTHONPATH", "{dir}/hook"),), run="proc", absent=("s",), timeout=120, note="before: after the error, multiprocessing's resource tracker 'died unexpectedly' (killed by the reaping) and KeyError tracebacks"),
    C("hang-compare-adaptive-lambda-1e5", "compare computed-torque --method adaptive --lambda 1e5 --no-plot --out c", 1, err=("computed-torque", "collapsed to about", "steps per dt"), changed=("c",), timeout=60),
]

RUN = "tp.simulate(controller, plant, trajectory, SimulationConfig(duration=0.01))"
"""A 10-step run of pd on the twolink."""
NAN_Q = f"__import__('dataclasses').replace({RUN}, q=np.where(np.arange(11)[:, None] >= 5, np.nan, {RUN}.q))"
"""That run with q NaN from its sample 5 (t = 0.005 s) on."""

LIMITS_LIBRARY: list[LibCase] = [
    # a wrong type names the parameter and what was expected, not an AttributeError inside
    LibCase("library-compute_metrics-none", "tp.compute_metrics(None)", ("result", "SimulationResult")),
    LibCase("library-compute_metrics-string", "tp.compute_metrics('run.npz')", ("result", "SimulationResult", "str")),
    LibCase("library-compute_metrics-nan-result", f"tp.compute_metrics({NAN_Q})", ("result", "non-finite q", "t = 0.005 s")),
    LibCase("library-inertial_parameters-robot", "__import__('twolink_pin.model.parameters').model.parameters.inertial_parameters(robot)", ("model", "pinocchio.Model", "RobotModel")),
    LibCase("library-inertial_parameters-none", "__import__('twolink_pin.model.parameters').model.parameters.inertial_parameters(None)", ("model", "pinocchio.Model")),
    LibCase("library-default_trajectory-string", "tp.default_trajectory('twolink')", ("robot", "RobotModel", "str")),
    LibCase("library-build_trajectory-model", "tp.build_trajectory(model)", ("robot", "RobotModel")),
    LibCase("library-excitation_trajectory-none", "tp.excitation_trajectory(None)", ("robot", "RobotModel")),
    LibCase("library-optimise_excitation-string", "tp.optimise_excitation('ur5')", ("robot", "RobotModel")),
    LibCase("library-simulate_log-string", "tp.simulate_log('twolink', trajectory)", ("robot", "RobotModel")),
    LibCase("library-identify-log-string", "tp.identify('log.npz', robot)", ("log", "RunLog")),
    LibCase("library-identify-robot-model", "tp.identify(tp.simulate_log(robot, trajectory, duration=0.5), model)", ("robot", "RobotModel")),
    LibCase("library-read_log-none", "tp.read_log(None, 2)", ("path", "file path")),
    LibCase("library-read_trajectory_file-int", "tp.read_trajectory_file(3, robot)", ("path", "file path")),
    LibCase("library-example_robot_urdf-int", "tp.example_robot_urdf(3)", ("relative", "str")),
]
# fmt: on
