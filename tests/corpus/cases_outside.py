"""Corpus cases of issue 30: data from outside (logs and bags, via-pose files) and user code
everywhere it runs. Kept apart from ``cases.py`` (same classes, same rules; see its docstring):
each case failed on 934c0e3.
"""

from __future__ import annotations

import shlex

from corpus.bags import bag_file, log_file, ros2_bag
from corpus.spec import Case, blob, text

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
# fmt: on

OUTSIDE: list[Case] = [*LOGS]
"""Every case of this file."""
