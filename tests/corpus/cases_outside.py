"""Corpus cases of issue 30: data from outside (logs and bags, via-pose files) and user code
everywhere it runs. Kept apart from ``cases.py`` (same classes, same rules; see its docstring):
each case failed on 934c0e3.
"""

from __future__ import annotations

import shlex

from corpus.bags import bag_file, log_file, ros2_bag
from corpus.spec import Case, LibCase, blob, folder, text, urdf

LAW = "{corpus}/laws"
SIM = "--duration 0.5"


def C(id: str, argv: str, exit: int | tuple[int, ...], **kw: object) -> Case:
    """A case; ``argv`` is split like a shell would."""
    return Case(id, tuple(shlex.split(argv)), exit, **kw)  # type: ignore[arg-type]


def bag(defect: str) -> tuple:
    """Setup: ``run.bag`` (ROS 1) with ``defect``."""
    return (blob("run.bag", bag_file(defect)),)


def folder_bag(defect: str) -> tuple:
    """Setup: the ROS 2 bag folder ``run`` with ``defect``."""
    return tuple(blob(path, content) for path, content in ros2_bag(defect))


BROKEN_YAML = (
    "rosbag2_bagfile_information:\n  version: 8\n  message_count: [oops\n  storage_identifier: sqlite3\n"
)

# fmt: off
# == Logs are data from outside: a bag or log that is not a valid log is refused, naming where ========
LOGS = [
    C("nonfinite-identify-bag-nan-position", "identify --data run.bag", 2, err=("message 500", "position", "'joint2'", "nan", "t = 0.5 s"), setup=bag("nan-position"), not_err=("internal error",)),
    C("nonfinite-identify-bag-inf-effort", "identify --data run.bag", 2, err=("message 700", "effort", "'joint1'", "inf"), setup=bag("inf-effort"), not_err=("internal error",)),
    C("nonfinite-identify-bag-nan-velocity", "identify --data run.bag", 2, err=("message 800", "velocity", "'joint1'", "nan"), setup=bag("nan-velocity"), note="a logged velocity is a check only, but a NaN in it means the log is broken"),
    C("nonfinite-identify-bag-nan-command", "identify --data run.bag --torque-topic /commands", 2, err=("/commands message 900", "effort", "'joint2'", "nan"), setup=bag("nan-command")),
    C("nonfinite-identify-ros2-bag-nan-position", "identify --data run", 2, err=("message 500", "position", "'joint2'", "nan"), setup=folder_bag("nan-position")),
    C("wrong-identify-bag-joint-named-twice", "identify --data run.bag", 2, err=("message 300", "'joint1'", "twice"), setup=bag("joint-twice"), note="the last value would silently win"),
    C("wrong-identify-bag-time-repeats", "identify --data run.bag", 2, err=("messages 999 and 1000", "repeats", "t = 0.999 s"), setup=bag("time-repeats"), note="two samples for one time: one was dropped silently"),
    C("wrong-identify-bag-time-backwards", "identify --data run.bag", 2, err=("message 1000", "backwards", "message 999"), setup=bag("time-backwards")),
    C("wrong-identify-ros2-bag-time-backwards-stored-in-order", "identify --data run", 2, err=("messages 950 and 951", "repeats or goes backwards", "0.5 ms apart", "t = 0.95 s"), setup=folder_bag("time-backwards-received"), note="a clock reset stored in stamp order reads as interleaved half steps"),
    C("wrong-identify-bag-time-near-repeat", "identify --data run.bag", 2, err=("messages", "0.4 ms apart", "half"), setup=bag("time-near-repeat")),
    C("wrong-identify-bag-time-jumps", "identify --data run.bag", 2, err=("messages 999 and 1000", "jumps", "t = 0.999 s"), setup=bag("time-jumps")),
    C("wrong-identify-npz-time-jumps", "identify --data log.npz", 2, err=("sample 1000", "column 't'", "jumps", "3601"), setup=(blob("log.npz", log_file("time-jumps", ".npz")),), note="resampled, an hour-long jump made a log of a motion that never happened"),
    C("wrong-identify-csv-time-gap", "identify --data log.csv", 2, err=("data row 1001", "line 1002", "jumps", "1.02 s"), setup=(blob("log.csv", log_file("time-gap", ".csv")),)),
    C("unclear-identify-ros2-bag-metadata-not-yaml", "identify --data run", 2, err=("metadata.yaml", "not valid YAML", "line 4, column 21"), setup=(*folder_bag("none"), text("run/metadata.yaml", BROKEN_YAML)), note="one line saying where, not a YAML parser's dump"),
    C("unclear-identify-ros2-bag-metadata-binary", "identify --data run", 2, err=("metadata.yaml", "not UTF-8"), setup=(*folder_bag("none"), blob("run/metadata.yaml", b"\x00\xff\xfe")), not_err=("codec",)),
    C("hang-identify-bag-larger-than-memory", "identify --data run.bag", 2, err=("run.bag", "MiB on disk", "3 ×", "0.09537 MiB of memory are available"), setup=bag("none"), env=(("TWOLINK_PIN_MEMORY", "100000"),), run="proc", note="refused by its size before it is read; the limit is the machine's available memory unless TWOLINK_PIN_MEMORY says"),
]

# == Via-pose files: a number that is not finite or absurd is refused naming its row and column ======
POSES = "times = [0.0, 2.0, 4.0, 6.0, 8.0]\npositions = [{}]\nrpy = [{}]\n"
P_ROWS = ["[0.45, 0.10, 0.40]", "[0.45, -0.10, 0.40]", "[0.45, -0.10, 0.20]", "[0.45, 0.10, 0.20]", "[0.45, 0.10, 0.40]"]
R_ROWS = ["[3.141592653589793, 0.0, -1.5707963267948966]", "[3.141592653589793, 0.2, -1.5707963267948966]", "[3.141592653589793, 0.2, -1.2707963267948966]", "[2.941592653589793, 0.0, -1.2707963267948966]", "[3.141592653589793, 0.0, -1.5707963267948966]"]


def poses(name: str, positions: dict[int, str] | None = None, rpy: dict[int, str] | None = None) -> tuple:
    """Setup: the task-space tutorial's square of via poses for the UR5 with rows replaced."""
    p = [(positions or {}).get(i, row) for i, row in enumerate(P_ROWS)]
    r = [(rpy or {}).get(i, row) for i, row in enumerate(R_ROWS)]
    return (text(name, POSES.format(", ".join(p), ", ".join(r))),)


UR5 = f"--robot ur5 {SIM}"
VIA_POSES = [
    C("nonfinite-simulate-poses-rpy-1e300", f"simulate pd {UR5} --trajectory p.toml", 2, err=("p.toml", "rpy[1][2]", "1e+300", "±100 rad"), setup=poses("p.toml", rpy={1: "[3.14, 0.2, 1e300]"}), note="sin(1e300) is no angle: the run succeeded with a garbage orientation"),
    C("nonfinite-simulate-poses-rpy-1e6", f"simulate pd {UR5} --trajectory p.toml", 2, err=("rpy[2][0]", "1000000", "±100 rad"), setup=poses("p.toml", rpy={2: "[1e6, 0.2, -1.27]"})),
    C("nonfinite-simulate-poses-rpy-nan", f"simulate pd {UR5} --trajectory p.toml", 2, err=("rpy[3][1]", "nan"), setup=poses("p.toml", rpy={3: "[2.94, nan, -1.27]"})),
    C("nonfinite-simulate-poses-position-1e300", f"simulate pd {UR5} --trajectory p.toml", 2, err=("positions[2][1]", "1e+300", "±100 m"), setup=poses("p.toml", positions={2: "[0.45, 1e300, 0.2]"}), note="was an overflow warning and an IK error at 'inf m'"),
    C("nonfinite-simulate-poses-position-inf", f"simulate pd {UR5} --trajectory p.toml", 2, err=("positions[3][2]", "-inf"), setup=poses("p.toml", positions={3: "[0.45, 0.1, -inf]"})),
    C("nonfinite-simulate-poses-seed-1e300", f"simulate pd {UR5} --trajectory p.toml", 2, err=("seed[4]", "1e+300", "±100 rad"), setup=(text("p.toml", POSES.format(", ".join(P_ROWS), ", ".join(R_ROWS)) + "seed = [0, -1.5, 1.5, -1.5, 1e300, 0]\n"),)),
    C("nonfinite-simulate-joints-continuous-1e300", "simulate pd --robot continuous.urdf --duration 0.5 --trajectory j.toml", 2, err=("joints[1][0]", "1e+300", "±100 rad"), setup=(urdf("continuous"), text("j.toml", "times = [0, 1, 2]\njoints = [[0, 0], [1e300, 0.3], [0, 0]]\n")), note="a joint without limits (continuous) has no other bound"),
]

# == User code everywhere it runs (laws/hostile.py, sleeps_on_import.py, import_raises_line.py) =========
H = f"{LAW}/hostile.py"
NOT_OURS = ("twolink_pin_user_", "internal error")
"""Never a module name of ours, never a bug of ours."""
USER_LAWS = [
    C("usercode-simulate-law-init-raises-file-line", f"simulate {H}:InitRaises {SIM}", 2, err=("corpus-hostile-init-raises", "RuntimeError", "hostile.py:52"), not_err=NOT_OURS, note="was the module name twolink_pin_user_hostile_<hash>"),
    C("usercode-simulate-law-scaled-gains-raises-file-line", f"simulate {H}:ScaledGainsRaises {SIM}", 2, err=("KeyError", "hostile.py:93"), not_err=NOT_OURS),
    C("usercode-simulate-law-init-exits", f"simulate {H}:InitExits {SIM} --save run.npz", 2, err=("sys.exit(0)", "hostile.py:72"), absent=("run.npz",), note="sys.exit(0) while the law is built ended the command silently with exit 0"),
    C("usercode-simulate-law-init-sleeps-timeout", f"simulate {H}:InitSleeps {SIM} --timeout 2", 1, err=("--timeout 2 s", "hostile.py:62", "corpus-hostile-init-sleeps"), run="proc", timeout=30),
    C("usercode-simulate-law-scaled-gains-spins-timeout", f"simulate {H}:ScaledGainsSpins {SIM} --timeout 2", 1, err=("--timeout 2 s", "hostile.py:82"), run="proc", timeout=30),
    C("usercode-simulate-law-file-sleeps-on-import-timeout", f"simulate {LAW}/sleeps_on_import.py:Law {SIM} --timeout 2", 1, err=("--timeout 2 s", "sleeps_on_import.py:5"), run="proc", timeout=30),
    C("usercode-simulate-law-file-import-raises-line", f"simulate {LAW}/import_raises_line.py:Law {SIM}", 2, err=("ImportError", "import_raises_line.py:5"), not_err=NOT_OURS),
    C("usercode-simulate-law-complex-torque", f"simulate {H}:ComplexTorque {SIM}", 1, err=("corpus-hostile-complex-torque", "complex128", "real numbers", "tau.real"), not_err=NOT_OURS),
    C("usercode-simulate-law-string-torque", f"simulate {H}:StringTorque {SIM}", 1, err=("corpus-hostile-string-torque", "<U", "real numbers"), not_err=NOT_OURS),
    C("usercode-simulate-law-object-torque-adaptive", f"simulate {H}:ObjectTorque {SIM} --method adaptive", 1, err=("corpus-hostile-object-torque", "object", "real numbers"), not_err=NOT_OURS),
    C("usercode-simulate-law-chdir-save", f"simulate {H}:Chdir {SIM} --save run.npz", 0, setup=(folder("elsewhere"),), exists=("run.npz",), absent=("elsewhere/run.npz",), note="the output goes where the command was started, not where the law moved"),
    C("usercode-compare-law-chdir-out", f"compare {H}:Chdir pd {SIM} --no-plot --out c", 0, setup=(folder("elsewhere"),), exists=("c/comparison.json",), absent=("elsewhere/c",)),
    C("usercode-simulate-law-starts-process", f"simulate {H}:StartsProcess {SIM}", 0, run="proc", note="the law's 'sleep 600' is ended with the command (the runner finds every process that inherited the case's marker)"),
    C("usercode-simulate-law-starts-multiprocessing", f"simulate {H}:StartsMultiprocessing {SIM}", 0, run="proc", timeout=20, note="Python's exit waited 600 s for the law's non-daemon child"),
    C("usercode-simulate-law-state-named-twice", f"simulate {H}:StateNamedTwice {SIM}", 2, err=("corpus-hostile-state-named-twice", "'s' at entries [0, 1]", "named once")),
    C("usercode-simulate-law-state-name-empty", f"simulate {H}:StateNameEmpty {SIM}", 2, err=("state_variables()[0].name", "''", "non-empty")),
    C("usercode-simulate-law-initial-state-wrong-size", f"simulate {H}:StateWrongSize {SIM}", 2, err=("initial_state()", "(3,)", "nz = 2", "(a, b)")),
]

EYE3 = "np.stack([np.eye(3)] * 3)"
OUTSIDE_LIBRARY = [
    LibCase("library-pose_trajectory-position-1e300", f"tp.trajectory.pose_trajectory(robot, (0, 1, 2), np.array([[0.3, 0, 0], [0.3, 1e300, 0], [0.3, 0, 0]]), {EYE3})", ("positions[1][1]", "1e+300", "±100 m")),
    LibCase("library-pose_trajectory-rotation-nan", "tp.trajectory.pose_trajectory(robot, (0, 1, 2), np.array([[0.3, 0, 0]] * 3), np.array([np.eye(3), np.full((3, 3), np.nan), np.eye(3)]))", ("rotations[1][0][0]", "nan")),
]
# fmt: on

OUTSIDE: list[Case] = [*LOGS, *VIA_POSES, *USER_LAWS]
"""Every case of this file."""
