"""The bad-input corpus: every case with its expected outcome, grouped by class.

Ids read ``class-command-what``. Expected exit statuses: 0 success; 2 a refusal of bad input
(one line ``twolink-pin: error: ...`` or argparse's ``twolink-pin <cmd>: error: ...``); 1 a
run that failed (a diverged simulation or a law that raised: the message names the law and
the time ``t = ... s``); 130 interrupted. A tuple of statuses means "any of these, as long as
every invariant holds" — used where more than one outcome is sound (e.g. a refusal or a
correct answer, never a wrong one). Words are matched case-insensitively; ``"a|b"`` accepts
either. Where an expectation is a judgement, ``note=`` says why.

Bounds in messages are read from the library where it declares them, so a case follows a
bound that changes.
"""

from __future__ import annotations

import shlex
import zlib
from collections import Counter

import numpy as np

from corpus.cases_outside import OUTSIDE, OUTSIDE_LIBRARY
from corpus.spec import (
    SIGINT,
    SIGTERM,
    Case,
    LibCase,
    Step,
    blob,
    chmod,
    cli,
    contains,
    crlf,
    deep_nesting,
    device,
    fifo,
    finite_file,
    fk_closed_form,
    folder,
    garbage,
    ik_reaches,
    json_at,
    json_file,
    many_links,
    npz_arrays,
    npz_bomb,
    npz_from_saved,
    npz_huge_header,
    npz_pickled,
    oversize,
    peak_within_limits,
    secret_kept,
    still_symlink,
    strict_json,
    symlink,
    text,
    truncate,
    twolink,
    unix_socket,
    urdf,
    urdf_roundtrip,
    utf8_bom,
    utf16,
    whole_or_absent,
)
from corpus.spec import _zip as zip_of


def _bound(module: str, name: str, default: float) -> float:
    import importlib

    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError):
        return default


MAX_SAMPLES = int(_bound("twolink_pin.studies.sweep", "MAX_SAMPLES", 10_000_000))
MAX_CHUNK = int(_bound("twolink_pin.studies.sweep", "MAX_CHUNK", 100_000))
MAX_STEPS = int(_bound("twolink_pin.simulation.config", "MAX_STEPS", 10_000_000))
MAX_WORKERS = int(_bound("twolink_pin.report.options", "MAX_WORKERS", 64))
MAX_OFFSET = _bound("twolink_pin.cli.parser", "MAX_OFFSET", 100.0)
MAX_PAYLOAD = _bound("twolink_pin.cli.common_options", "MAX_PAYLOAD", 1e4)
MAX_DURATION = _bound("twolink_pin.cli.parser", "MAX_DURATION", 1e6)
MAX_VIA_POINTS = int(_bound("twolink_pin.trajectory.file", "MAX_VIA_POINTS", 24))
MAX_TRAJECTORY_BYTES = int(_bound("twolink_pin.trajectory.file", "MAX_TRAJECTORY_BYTES", 1 << 20))
GiB = 2**30


def C(id: str, argv: str | tuple[str | bytes, ...], exit: int | tuple[int, ...], **kw: object) -> Case:
    """A case; a string argv is split like a shell would."""
    args = tuple(shlex.split(argv)) if isinstance(argv, str) else tuple(argv)
    return Case(id, args, exit, **kw)  # type: ignore[arg-type]


SIM = "--duration 0.5"
STEP_REFUSED = "--dt = 0.001 is invalid: expected at most"
"""The step check's refusal (issue 50): a step beyond RK4's bound on the start's fastest mode."""
"""A short run: 500 steps."""
REP = "--duration 1 --workers 1 --no-animation --no-limits-section --controller pd"
"""A cheap report: one law, one second, in this process, no animation."""
LAW = "{corpus}/laws"
SAVED = cli("simulate", "pd", "--duration", "0.5", "--save", "run.npz")
"""A saved result ``run.npz`` of the twolink."""
RO = (folder("ro"), chmod("ro", 0o555))
"""A read-only folder ``ro``."""
USER = text("mine/notes.txt", "my notes, not twolink-pin's\n")
"""A user's folder ``mine`` with a file in it."""
NOT_DIR = "not a directory|is a file"
NOT_REGULAR = "not a regular file|device|pipe|fifo"
EMPTY_PATH = "empty path|empty string|''|\"\"|no path"
NONEMPTY = "non-empty|not empty"
PANDA_FOLD = (
    "times = [0.0, 2.0, 3.0, 5.0]\n"
    "positions = [[0.32, 0.0, 0.15], [0.32, 0.0, 0.45], [0.32, 0.0, 0.45], [0.32, 0.0, 0.15]]\n"
    "rpy = [[3.141592653589793, 0.0, 0.0], [3.141592653589793, 0.0, 0.0], [3.141592653589793, 0.0, 0.0], [3.141592653589793, 0.0, 0.0]]\n"
    "seed = [0.0, -0.3, 0.0, -2.95, 0.0, 2.6, 0.785]\n"
)
"""examples/panda_fold_pose.toml (docs/limits.md): the Panda's hand lowered near its base, the elbow folded."""
VIA_JSON = '{"times": [0, 1, 2], "joints": [[0, 0], [0.5, 0.3], [0, 0]]}\n'
"""A valid joint-space trajectory file for the twolink."""


def via(name: str, content: str) -> Step:
    """A trajectory file ``name`` in the case folder."""
    return text(name, content)


# fmt: off
# The cases are a table, one case per line: ruff format would spread each over a dozen lines.

# == 1. Data loss ==================================================================================
# An output path must never destroy what the user had: a folder of theirs, a device, a file
# where a folder was expected. A command's own folder is replaced as a whole (not merged).
DATALOSS = [
    # -- compare --out
    C("dataloss-compare-user-folder", f"compare pd {SIM} --no-plot --out mine", 2, err=("mine", NONEMPTY), setup=(USER,), absent=("mine/comparison.md",)),
    C("dataloss-compare-user-folder-hidden-file", f"compare pd {SIM} --no-plot --out mine", 2, err=("mine", NONEMPTY), setup=(text("mine/.keep", ""),)),
    C("dataloss-compare-user-folder-only-subfolder", f"compare pd {SIM} --no-plot --out mine", 2, err=("mine", NONEMPTY), setup=(folder("mine/data"),)),
    C("dataloss-compare-out-is-file", f"compare pd {SIM} --no-plot --out results.txt", 2, err=("results.txt", NOT_DIR), setup=(text("results.txt", "mine\n"),)),
    C("dataloss-compare-out-symlink-to-user-folder", f"compare pd {SIM} --no-plot --out link", 2, err=("link",), setup=(USER, symlink("link", "mine")), checks=(still_symlink("link"),)),
    C("dataloss-compare-out-parent-is-file", f"compare pd {SIM} --no-plot --out notes.txt/c", 2, err=("notes.txt", NOT_DIR), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-compare-out-cwd", f"compare pd {SIM} --no-plot --out .", 2, err=(NONEMPTY,), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-compare-out-empty-string", ("compare", "pd", "--duration", "0.5", "--no-plot", "--out", ""), 2, err=(EMPTY_PATH,), setup=(text("notes.txt", "x\n"),), note="'' is no path; it must not mean the working directory"),
    C("dataloss-compare-default-out-user-folder", f"compare pd {SIM} --no-plot", 2, err=("out/compare", NONEMPTY), setup=(text("out/compare/draft.md", "mine\n"),)),
    C("dataloss-compare-out-device-node", f"compare pd {SIM} --no-plot --out null", 2, err=("null", NOT_DIR), setup=(device("null", "null"),), chardev=("null",)),
    C("dataloss-compare-out-fifo", f"compare pd {SIM} --no-plot --out pipe", 2, err=("pipe", NOT_DIR), setup=(fifo("pipe"),), timeout=20),
    C("dataloss-compare-twice-own-folder", f"compare pd {SIM} --no-plot --out c", 0, setup=(cli("compare", "pd", "--duration", "0.5", "--no-plot", "--out", "c"),), changed=("c",), exists=("c/comparison.md", "c/.twolink-pin-compare")),
    C("dataloss-compare-twice-no-stale-figures", f"compare pd {SIM} --no-plot --out c", 0, setup=(cli("compare", "pd", "--duration", "0.5", "--out", "c"),), changed=("c",), exists=("c/comparison.md",), absent=("c/figures",), note="the folder is replaced as a whole: figures of the first run must not survive a run without figures"),
    C("dataloss-compare-own-folder-with-user-file", f"compare pd {SIM} --no-plot --out c", 2, err=("thesis.tex",), setup=(cli("compare", "pd", "--duration", "0.5", "--no-plot", "--out", "c"), text("c/thesis.tex", "my thesis\n")), note="judgement: the folder carries the marker, but the user has since put a file of theirs in it; replacing the folder would delete it"),
    # -- sweep --out
    C("dataloss-sweep-user-folder", f"sweep pd --samples 3 {SIM} --no-plot --out mine", 2, err=("mine", NONEMPTY), setup=(USER,), absent=("mine/summary.json",)),
    C("dataloss-sweep-user-folder-keep-trajectories", f"sweep pd --samples 3 {SIM} --no-plot --keep-trajectories --out mine", 2, err=("mine", NONEMPTY), setup=(USER,)),
    C("dataloss-sweep-out-is-file", f"sweep pd --samples 3 {SIM} --no-plot --out runs.csv", 2, err=("runs.csv", NOT_DIR), setup=(text("runs.csv", "a,b\n1,2\n"),)),
    C("dataloss-sweep-default-out-user-folder", f"sweep pd --samples 3 {SIM} --no-plot", 2, err=("out/sweep", NONEMPTY), setup=(text("out/sweep/data.csv", "1,2\n"),)),
    C("dataloss-sweep-out-cwd", f"sweep pd --samples 3 {SIM} --no-plot --out .", 2, err=(NONEMPTY,), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-sweep-out-empty-string", ("sweep", "pd", "--samples", "3", "--duration", "0.5", "--no-plot", "--out", ""), 2, err=(EMPTY_PATH,), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-sweep-out-fifo", f"sweep pd --samples 3 {SIM} --no-plot --out pipe", 2, err=("pipe", NOT_DIR), setup=(fifo("pipe"),), timeout=20),
    C("dataloss-sweep-twice-own-folder", f"sweep pd --samples 3 {SIM} --no-plot --out s", 0, setup=(cli("sweep", "pd", "--samples", "3", "--duration", "0.5", "--no-plot", "--out", "s"),), changed=("s",), exists=("s/summary.json", "s/runs.csv")),
    C("dataloss-sweep-twice-no-stale-trajectories", f"sweep pd --samples 3 {SIM} --no-plot --out s", 0, setup=(cli("sweep", "pd", "--samples", "3", "--duration", "0.5", "--no-plot", "--keep-trajectories", "--out", "s"),), changed=("s",), absent=("s/trajectories-0000000.npz",)),
    # -- report --out
    C("dataloss-report-user-folder", f"report {REP} --out site", 2, err=("site", NONEMPTY), setup=(text("site/index.html", "<p>my page</p>\n"),)),
    C("dataloss-report-out-is-file", f"report {REP} --out report.html", 2, err=("report.html", NOT_DIR), setup=(text("report.html", "<p>mine</p>\n"),)),
    C("dataloss-report-default-out-user-folder", f"report {REP}", 2, err=("out", NONEMPTY), setup=(text("out/paper.pdf", "%PDF-1.4\n"),)),
    C("dataloss-report-out-symlink-to-user-folder", f"report {REP} --out link", 2, err=("link",), setup=(USER, symlink("link", "mine")), checks=(still_symlink("link"),)),
    C("dataloss-report-out-cwd", f"report {REP} --out .", 2, err=(NONEMPTY,), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-report-out-empty-string", ("report", *REP.split(), "--out", ""), 2, err=(EMPTY_PATH,), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-report-twice-own-folder", f"report {REP} --out r", 0, setup=(cli("report", *REP.split(), "--out", "r"),), changed=("r",), exists=("r/index.html", "r/results.json")),
    # -- the real /dev, in a private /dev so that a regression cannot replace the machine's
    C("dataloss-simulate-save-dev-full", f"simulate pd {SIM} --save /dev/full", 2, err=("/dev/full", NOT_REGULAR), run="devsandbox"),
    C("dataloss-simulate-save-dev-null", f"simulate pd {SIM} --save /dev/null", 2, err=("/dev/null", NOT_REGULAR), run="devsandbox"),
    C("dataloss-animate-html-dev-null", f"animate pd {SIM} --html /dev/null", 2, err=("/dev/null", NOT_REGULAR), run="devsandbox"),
    C("dataloss-info-write-urdf-dev-null", "info --payload 1 --write-urdf /dev/null", 2, err=("/dev/null", NOT_REGULAR), run="devsandbox"),
    C("dataloss-info-write-urdf-dev-full", "info --payload 1 --write-urdf /dev/full", 2, err=("/dev/full", NOT_REGULAR), run="devsandbox"),
    C("dataloss-trajectory-plot-dev-null", "trajectory --plot /dev/null", 2, err=("/dev/null", NOT_DIR), run="devsandbox"),
    C("dataloss-compare-out-dev-null", f"compare pd {SIM} --no-plot --out /dev/null", 2, err=("/dev/null", NOT_DIR), run="devsandbox"),
    # -- devices in the user's folder (mknod), in this process
    C("dataloss-simulate-save-device-node", f"simulate pd {SIM} --save null.npz", 2, err=("null.npz", NOT_REGULAR), setup=(device("null.npz", "null"),), chardev=("null.npz",)),
    C("dataloss-animate-html-device-node", f"animate pd {SIM} --html full.html", 2, err=("full.html", NOT_REGULAR), setup=(device("full.html", "full"),), chardev=("full.html",)),
    C("dataloss-info-write-urdf-device-node", "info --payload 1 --write-urdf zero.urdf", 2, err=("zero.urdf", NOT_REGULAR), setup=(device("zero.urdf", "zero"),), chardev=("zero.urdf",)),
    C("dataloss-simulate-plot-device-node", f"simulate pd {SIM} --plot figs", 2, err=("figs", NOT_DIR), setup=(device("figs", "null"),), chardev=("figs",)),
    # -- FIFOs as outputs: never opened (opening one for writing blocks until a reader comes)
    C("dataloss-simulate-save-fifo", f"simulate pd {SIM} --save pipe.npz", 2, err=("pipe.npz", NOT_REGULAR), setup=(fifo("pipe.npz"),), timeout=20),
    C("dataloss-animate-html-fifo", f"animate pd {SIM} --html pipe.html", 2, err=("pipe.html", NOT_REGULAR), setup=(fifo("pipe.html"),), timeout=20),
    C("dataloss-info-write-urdf-fifo", "info --payload 1 --write-urdf pipe.urdf", 2, err=("pipe.urdf", NOT_REGULAR), setup=(fifo("pipe.urdf"),), timeout=20),
    C("dataloss-trajectory-plot-fifo", "trajectory --plot pipe", 2, err=("pipe", NOT_DIR), setup=(fifo("pipe"),), timeout=20),
    # -- a file where a folder is expected, a folder where a file is expected
    C("dataloss-simulate-plot-is-file", f"simulate pd {SIM} --plot figs", 2, err=("figs", NOT_DIR), setup=(text("figs", "my list of figures\n"),)),
    C("dataloss-trajectory-plot-is-file", "trajectory --plot figs", 2, err=("figs", NOT_DIR), setup=(text("figs", "my list of figures\n"),)),
    C("dataloss-simulate-save-parent-is-file", f"simulate pd {SIM} --save notes/run.npz", 2, err=("notes", NOT_DIR), setup=(text("notes", "x\n"),)),
    C("dataloss-animate-html-parent-is-file", f"animate pd {SIM} --html notes/a.html", 2, err=("notes", NOT_DIR), setup=(text("notes", "x\n"),)),
    C("dataloss-info-write-urdf-parent-is-file", "info --payload 1 --write-urdf notes/heavy.urdf", 2, err=("notes", NOT_DIR), setup=(text("notes", "x\n"),)),
    C("dataloss-simulate-save-is-folder", f"simulate pd {SIM} --save results", 2, err=("results", "directory"), setup=(text("results/a.txt", "x\n"),)),
    C("dataloss-animate-html-is-folder", f"animate pd {SIM} --html page", 2, err=("page", "directory"), setup=(folder("page"),)),
    C("dataloss-info-write-urdf-is-folder", "info --payload 1 --write-urdf variants", 2, err=("variants", "directory"), setup=(folder("variants"),)),
    # -- empty paths
    C("dataloss-simulate-save-empty-string", ("simulate", "pd", "--duration", "0.5", "--save", ""), 2, err=(EMPTY_PATH,)),
    C("dataloss-simulate-plot-empty-string", ("simulate", "pd", "--duration", "0.5", "--plot", ""), 2, err=(EMPTY_PATH,), setup=(text("notes.txt", "x\n"),)),
    C("dataloss-animate-html-empty-string", ("animate", "pd", "--duration", "0.5", "--html", ""), 2, err=(EMPTY_PATH,), timeout=10, note="'' must not fall back to the live viewer either"),
    C("dataloss-info-write-urdf-empty-string", ("info", "--payload", "1", "--write-urdf", ""), 2, err=(EMPTY_PATH,)),
    # -- replacing a file is what an output path means; the input is not an output
    C("dataloss-simulate-save-replaces-own-file", f"simulate pd {SIM} --save run.npz", 0, setup=(SAVED,), changed=("run.npz",), exists=("run.npz",)),
    C("dataloss-simulate-save-through-symlink", f"simulate pd {SIM} --save link.npz", 0, setup=(cli("simulate", "pd", "--duration", "0.5", "--save", "store/run.npz"), symlink("link.npz", "store/run.npz")), changed=("store/run.npz",), checks=(still_symlink("link.npz"),)),
    C("dataloss-info-write-urdf-over-its-input", "info --robot arm.urdf --payload 1 --write-urdf arm.urdf", 2, err=("arm.urdf",), setup=(twolink("arm.urdf"),), note="judgement: writing the payload variant over the description being read destroys the original; refuse")
]


# == 2. Wrong answers accepted ======================================================================
# A value the parser would change behind the user's back, an answer that does not hold, an
# option that is silently ignored.
IK_TARGETS = {
    "report-row-3": (0.48, -0.1),
    "outer-boundary": (0.62, 0.0),
    "inner-boundary": (0.14, 0.0),
    "straight-up": (0.0, 0.3),
    "behind": (-0.5, 0.1),
    "lower-right": (0.3, -0.3),
    "just-inside-outer": (0.6199999999, 0.0),
    "just-outside-inner": (0.1400000001, 0.0),
    "outer-boundary-rounding": (0.62, 1e-17),
    "negative-y-axis": (0.0, -0.61)
}
WRONG = [
    # -- XML entities and DTDs: Pinocchio's parser does not expand them, so they must be refused
    C("wrong-info-entity-mass", "info --robot entity_mass.urdf", 2, err=("entity_mass.urdf", "entit|DTD|DOCTYPE"), setup=(urdf("entity_mass"),)),
    C("wrong-simulate-entity-mass", f"simulate pd {SIM} --robot entity_mass.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("entity_mass"),)),
    C("wrong-report-entity-mass", f"report {REP} --robot entity_mass.urdf --out r", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("entity_mass"),), absent=("r",)),
    C("wrong-fk-entity-origin", "fk 0 0 --robot entity_origin.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("entity_origin"),)),
    C("wrong-trajectory-entity-origin", "trajectory --robot entity_origin.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("entity_origin"),)),
    C("wrong-info-billion-laughs", "info --robot billion_laughs.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("billion_laughs"),), run="proc", memory=3 * GiB, timeout=30),
    C("wrong-info-external-entity", "info --robot external_entity.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("external_entity"), text("secret.txt", "2.0 TOPSECRET-7f3a\n")), checks=(secret_kept("TOPSECRET-7f3a"),)),
    C("wrong-simulate-external-entity", f"simulate pd {SIM} --robot external_entity.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("external_entity"), text("secret.txt", "2.0 TOPSECRET-7f3a\n")), checks=(secret_kept("TOPSECRET-7f3a"),)),
    C("wrong-info-external-entity-fifo", "info --robot external_fifo.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("external_fifo"), fifo("entity.fifo")), run="proc", timeout=20),
    C("wrong-info-parameter-entity", "info --robot parameter_entity.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("parameter_entity"), text("secret.dtd", '<!ENTITY leak "TOPSECRET-dtd">\n')), checks=(secret_kept("TOPSECRET-dtd"),)),
    C("wrong-info-external-entity-http", "info --robot external_http.urdf", 2, err=("entit|DTD|DOCTYPE",), setup=(urdf("external_http"),), timeout=20),
    # -- ik on arms that are not planar 2R arms about z: the analytic 2R answer would be wrong, so a
    # refusal or a numerical answer that reaches the target (the issue asked for a refusal; ik has
    # since become a general solver, and a right answer is better than a refusal)
    C("wrong-ik-prismatic", "ik 0.3 0.2 --robot prismatic.urdf --json", (0, 2), err=("prismatic|reach",), setup=(urdf("prismatic"),), checks=(ik_reaches("prismatic.urdf", 0.3, 0.2),)),
    C("wrong-ik-axis-x", "ik 0.3 0.2 --robot axis_x.urdf --json", (0, 2), err=("axis|plane|reach",), setup=(urdf("axis_x"),), checks=(ik_reaches("axis_x.urdf", 0.3, 0.2),)),
    C("wrong-ik-arm3", "ik 0.3 0.2 --robot arm3.urdf --json", (0, 2), err=("2R|two|reach",), setup=(urdf("arm3"),), checks=(ik_reaches("arm3.urdf", 0.3, 0.2),)),
    C("wrong-ik-arm3-seed", "ik 0.3 0.2 --robot arm3.urdf --seed 0.1 0.2 0.3 --json", (0, 2), err=("reach",), setup=(urdf("arm3"),), checks=(ik_reaches("arm3.urdf", 0.3, 0.2),)),
    C("wrong-ik-twolink-seed", "ik 0.48 -0.1 --seed 0.1 0.2 --json", 0, checks=(ik_reaches(None, 0.48, -0.1),)),
    C("wrong-ik-twolink-z-out-of-plane", "ik 0.3 0.2 0.1", 2, err=("0.1", "reach|plane")),
    C("wrong-ik-ur5-3d", "ik 0.4 0.1 0.3 --robot ur5 --json", (0, 2), err=("reach",), checks=(ik_reaches("ur5", 0.4, 0.1, 0.3),)),
    C("wrong-ik-panda-3d", "ik 0.5 0.0 0.4 --robot panda --json", (0, 2), err=("reach",), checks=(ik_reaches("panda", 0.5, 0.0, 0.4),)),
    # -- ik on planar 2R arms laid out unlike the twolink: a right answer or a refusal, never a wrong answer
    C("wrong-ik-arm2", "ik 0.3 0.2 --robot arm2.urdf --json", 0, setup=(urdf("arm2"),), checks=(ik_reaches("arm2.urdf", 0.3, 0.2),)),
    C("wrong-ik-axis-minus-z", "ik 0.3 0.2 --robot axis_minus_z.urdf --json", (0, 2), err=("axis",), setup=(urdf("axis_minus_z"),), checks=(ik_reaches("axis_minus_z.urdf", 0.3, 0.2),)),
    C("wrong-ik-offset-elbow", "ik 0.3 0.2 --robot offset_elbow.urdf --json", (0, 2), err=("joint2|origin|offset",), setup=(urdf("offset_elbow"),), checks=(ik_reaches("offset_elbow.urdf", 0.3, 0.2),)),
    C("wrong-ik-offset-base", "ik 0.3 0.2 --robot offset_base.urdf --json", (0, 2), err=("joint1|origin|offset",), setup=(urdf("offset_base"),), checks=(ik_reaches("offset_base.urdf", 0.3, 0.2),)),
    C("wrong-ik-rotated-base", "ik 0.3 0.2 --robot rotated_base.urdf --json", (0, 2), err=("joint1|origin|rotat",), setup=(urdf("rotated_base"),), checks=(ik_reaches("rotated_base.urdf", 0.3, 0.2),)),
    C("wrong-ik-tool-offset", "ik 0.3 0.2 --robot tool_offset.urdf --json", (0, 2), err=("ee_link|end effector|offset",), setup=(urdf("tool_offset"),), checks=(ik_reaches("tool_offset.urdf", 0.3, 0.2),)),
    # -- ik on the twolink: fk of every answer is the target
    *(C(f"wrong-ik-twolink-{label}", ("ik", repr(x), repr(y), "--json"), 0, checks=(ik_reaches(None, x, y),)) for label, (x, y) in IK_TARGETS.items()),
    C("wrong-ik-twolink-payload", "ik 0.48 -0.1 --payload 2 --json", 0, checks=(ik_reaches(None, 0.48, -0.1),)),
    # -- options that must be honoured, and recorded where the output records settings
    C("wrong-report-saturate", f"report {REP} --saturate --out r", 0, checks=(json_at("r/results.json", "simulation.saturate", "==", True),)),
    C("wrong-report-friction-smoothing", "report --no-limits-section --duration 1 --workers 1 --no-animation --controller adaptive-friction --friction-smoothing 0.01 --out r", 0, checks=(json_at("r/results.json", "simulation.friction_smoothing", "==", 0.01),)),
    C("wrong-report-settings", "report --no-limits-section --duration 1 --workers 1 --no-animation --controller computed-torque --lambda 7 --q0-offset 0.2 -0.3 --dt 0.002 --payload 2 --out r", 0, checks=(json_at("r/results.json", "simulation.lambda.computed-torque", "==", 7.0), json_at("r/results.json", "simulation.q0_offset", "close", [0.2, -0.3]), json_at("r/results.json", "simulation.dt", "close", 0.002), json_at("r/results.json", "simulation.duration", "close", 1.0), json_at("r/results.json", "robot.payload_kg", "==", 2.0))),
    C("wrong-simulate-saturate", "simulate pd --duration 0.05 --gain kp=5000 --saturate --json", 0, checks=(peak_within_limits(),)),
    C("wrong-simulate-q0-offset", "simulate pd --duration 0.05 --q0-offset 0.2 --json", 0, checks=(json_at("stdout", "metrics.max.e", ">=", [0.2 - 1e-12, 0.2 - 1e-12]),)),
    C("wrong-simulate-dt", "simulate pd --duration 0.5 --dt 0.002 --json", 0, checks=(json_at("stdout", "dt", "close", 0.002),)),
    C("wrong-simulate-payload", "simulate adaptive --duration 0.05 --payload 2 --json", 0, checks=(json_at("stdout", "p_true", "close", [3.4 + 2 * (0.38**2 + 0.24**2), 0.4 + 2 * 0.24**2, 0.3 + 2 * 0.38 * 0.24]),)),
    C("wrong-info-write-urdf-roundtrip", "info --payload 2 --write-urdf heavy.urdf", 0, exists=("heavy.urdf",), checks=(urdf_roundtrip("heavy.urdf", 2.0),)),
    C("wrong-sweep-saturate", "sweep pd --samples 2 --duration 0.05 --gain kp=5000:5000 --saturate --no-plot --out s", 0, checks=(json_at("s/summary.json", "metrics.max_tau2.p95", "<=", 40.0 + 1e-9),)),
    C("wrong-sweep-summary-records-saturate", "sweep pd --samples 2 --duration 0.05 --saturate --no-plot --out s", 0, checks=(json_at("s/summary.json", "saturate", "==", True),), note="judgement: summary.json records duration, dt, gains, ...; a run's clipping belongs there too"),
    C("wrong-sweep-method-adaptive", f"sweep pd --samples 2 {SIM} --method adaptive --no-plot --out s", 2, err=("adaptive", "rk4"), absent=("s",)),
    C("wrong-simulate-lambda-on-pd", f"simulate pd {SIM} --lambda 3", 2, err=("pd", "λ|lambda")),
    C("wrong-sweep-lambda-on-pd", f"sweep pd --samples 2 {SIM} --lambda 3 --no-plot --out s", 2, err=("pd", "λ|lambda"), absent=("s",)),
    C("wrong-animate-from-and-controller", "animate pd --from run.npz --html a.html", 2, err=("--from", "pd"), setup=(SAVED,), absent=("a.html",), note="judgement: a law and a saved result at once is ambiguous; the law is silently ignored today"),
    C("wrong-animate-from-ignores-gain", "animate --from run.npz --gain kp=5 --html a.html", 2, err=("--gain",), setup=(SAVED,), absent=("a.html",), note="judgement: --gain has no effect on a saved result; refuse rather than ignore"),
    C("wrong-animate-from-other-robot", "animate --from run.npz --robot arm3.urdf --html a.html", 2, err=("run.npz", "3"), setup=(SAVED, urdf("arm3")), absent=("a.html",)),
    C("wrong-simulate-control-period-not-multiple", f"simulate pd {SIM} --control-period 0.0015", 2, err=("0.0015", "multiple")),
    C("wrong-simulate-adaptive-control-period", f"simulate pd {SIM} --method adaptive --control-period 0.01", 2, err=("control", "adaptive")),
    C("wrong-simulate-q0-offset-three-on-twolink", f"simulate pd {SIM} --q0-offset 0.1 0.2 0.3", 2, err=("0.3", "2 joints|2 values|one per joint")),
    C("wrong-simulate-gain-three-on-twolink", f"simulate pd {SIM} --gain kd=1,2,3", 2, err=("kd", "2")),
    C("wrong-simulate-qp-osc-posture-weight-above-one", f"simulate qp-osc --robot panda --gain posture_weight=2 {SIM}", 2, err=("posture_weight", "<= 1")),
    C("wrong-simulate-qp-osc-limit-scale-above-one", f"simulate qp-osc --robot panda --gain limit_scale=1.5 {SIM}", 2, err=("limit_scale", "<= 1")),
    C("wrong-simulate-qp-osc-limit-scale-zero", f"simulate qp-osc --robot panda --gain limit_scale=0 {SIM}", 2, err=("limit_scale", "0 < value")),
    C("wrong-simulate-qp-osc-horizon-negative", f"simulate qp-osc --robot panda --gain position_horizon=-0.1 {SIM}", 2, err=("position_horizon", "> 0")),
    C("wrong-simulate-qp-osc-horizon-two-on-panda", f"simulate qp-osc --robot panda --gain velocity_horizon=0.1,0.2 {SIM}", 2, err=("velocity_horizon", "7")),
    C("wrong-simulate-qp-osc-horizon-nan", f"simulate qp-osc --robot panda --gain position_horizon=nan {SIM}", 2, err=("position_horizon", "nan")),
    C("wrong-simulate-qp-osc-horizon-tiny", "simulate qp-osc --robot panda --gain velocity_horizon=1e-9 --duration 0.1 --json", (0, 1), err=("qp-osc", "t ="), note="a damper shorter than a step is a clamp RK4 follows roughly: a finished run or a failed one naming the time, never a traceback"),
    # -- options that would do nothing are refused, naming the option and why (issue 30); or done (issue 28 §4)
    C("wrong-noop-simulate-noise-seed-without-noise", f"simulate pd {SIM} --noise-seed 3", 2, err=("--noise-seed", "--sensor-noise")),
    C("wrong-noop-simulate-sensor-noise-zero", f"simulate pd {SIM} --sensor-noise 0,0", 2, err=("--sensor-noise", "0,0")),
    C("wrong-noop-simulate-wrench-after-the-run", f"simulate pd {SIM} --wrench 0,0,-20@1:2", 2, err=("--wrench", "0.5")),
    C("wrong-noop-simulate-wrench-between-two-steps", f"simulate pd {SIM} --wrench 1,0,0@0.0001:0.0002", 2, err=("--wrench", "0.0001")),
    C("wrong-noop-simulate-payload-step-after-the-run", f"simulate pd {SIM} --payload-step 2@5", 2, err=("--payload-step", "5 s")),
    C("wrong-noop-sweep-payload-step-after-the-run", f"sweep pd --samples 2 {SIM} --payload-step 2@0.5 --no-plot --out s", 2, err=("--payload-step", "0.5")),
    C("wrong-noop-animate-wrench-after-the-run", f"animate pd {SIM} --wrench 0,0,-20@9: --html a.html", 2, err=("--wrench", "9"), absent=("a.html",)),
    C("wrong-noop-simulate-friction-smoothing-without-friction", f"simulate pd {SIM} --friction-smoothing 0.01", 2, err=("--friction-smoothing", "pd", "--plant-friction on")),
    C("wrong-noop-simulate-plant-friction-off-without-friction", f"simulate pd {SIM} --plant-friction off", 2, err=("--plant-friction", "off", "pd")),
    C("wrong-noop-simulate-saturate-without-limits", f"simulate pd {SIM} --saturate --robot no_limits.urdf", 2, err=("--saturate", "effort limits"), setup=(urdf("no_limits"),)),
    C("wrong-noop-compare-lambda-for-laws-without-it", f"compare pd pd-gravity {SIM} --lambda 3 --out c", 2, err=("--lambda", "pd-gravity"), absent=("c",)),
    C("wrong-noop-compare-p0-for-laws-that-estimate-nothing", f"compare pd computed-torque {SIM} --p0 p.json --out c", 2, err=("--p0", "estimates"), setup=(text("p.json", "{}"),), absent=("c",)),
    C("wrong-noop-report-lambda-for-pd", f"report {REP} --lambda 3 --out r", 2, err=("--lambda", "pd"), absent=("r",)),
    C("wrong-noop-simulate-plant-friction-on-ur5", "simulate pd --robot ur5 --duration 0.05 --plant-friction on --json", 0, checks=(json_at("stdout", "plant_friction.viscous", "close", [0.4] * 6), json_at("stdout", "plant_friction.coulomb", "close", [0.2] * 6))),
    C("wrong-noop-simulate-plant-friction-on-panda-urdf-damping", "simulate pd --robot panda --duration 0.05 --plant-friction on --json", 0, checks=(json_at("stdout", "plant_friction.viscous", "close", [0.003] * 7),)),
    # -- trajectory files: values are numbers of the right kind, and they are what runs
    C("wrong-trajectory-file-period-true", "trajectory --trajectory via.toml", 2, err=("period", "true|bool"), setup=(via("via.toml", "times = [0, 0.5, 1]\njoints = [[0, 0], [0.5, 0.3], [0, 0]]\nperiod = true\n"),), note="TOML true is not a period of 1 s"),
    C("wrong-trajectory-file-times-booleans", "trajectory --trajectory via.json", 2, err=("times",), setup=(via("via.json", '{"times": [false, true, 2], "joints": [[0, 0], [0.5, 0.3], [0, 0]]}\n'),), note="JSON false and true are not times 0 s and 1 s"),
    C("wrong-trajectory-file-joints-strings", "trajectory --trajectory via.json", 2, err=("joints",), setup=(via("via.json", '{"times": [0, 1, 2], "joints": [["0", "0"], ["0.5", "0.3"], ["0", "0"]]}\n'),), note="JSON strings are not numbers"),
    C("wrong-trajectory-file-honoured", "trajectory --trajectory via.json --json", 0, setup=(via("via.json", VIA_JSON),), checks=(json_at("stdout", "via_q", "close", [[0, 0], [0.5, 0.3], [0, 0]]), json_at("stdout", "times", "close", [0, 1, 2]))),
    C("wrong-trajectory-file-toml-honoured", "trajectory --trajectory via.toml --json", 0, setup=(via("via.toml", "times = [0, 1, 2]\njoints = [[0, 0], [0.5, 0.3], [0, 0]]\n"),), checks=(json_at("stdout", "via_q", "close", [[0, 0], [0.5, 0.3], [0, 0]]),)),
    C("wrong-report-trajectory-file-honoured", f"report {REP} --trajectory via.json --out r", 0, setup=(via("via.json", VIA_JSON),), checks=(json_at("r/results.json", "trajectory.via_q", "close", [[0, 0], [0.5, 0.3], [0, 0]]),)),
    C("wrong-simulate-trajectory-file", f"simulate pd {SIM} --trajectory via.json", 0, setup=(via("via.json", VIA_JSON),)),
    C("wrong-sweep-trajectory-file", f"sweep pd --samples 2 {SIM} --trajectory via.json --no-plot --out s", 0, setup=(via("via.json", VIA_JSON),)),
    C("wrong-animate-trajectory-file", f"animate pd {SIM} --trajectory via.json --html a.html", 0, setup=(via("via.json", VIA_JSON),), exists=("a.html",))
]


# == 3. Hangs and unbounded work =====================================================================
# Inputs that would block, never end, or take memory or time without bound: refused up front.
HANG = [
    # -- FIFOs, devices, sockets, directories as input (real processes: a blocked read cannot be interrupted everywhere)
    C("hang-info-fifo-robot", "info --robot pipe.urdf", 2, err=("pipe.urdf", NOT_REGULAR), setup=(fifo("pipe.urdf"),), run="proc", timeout=20),
    C("hang-info-fifo-urdf-alias", "info --urdf pipe.xml", 2, err=("pipe.xml", NOT_REGULAR), setup=(fifo("pipe.xml"),), run="proc", timeout=20),
    C("hang-fk-fifo-no-suffix", "fk 0 0 --robot pipe", 2, err=("pipe", NOT_REGULAR), setup=(fifo("pipe"),), run="proc", timeout=20),
    C("hang-simulate-fifo-robot", f"simulate pd {SIM} --robot pipe.urdf", 2, err=("pipe.urdf", NOT_REGULAR), setup=(fifo("pipe.urdf"),), run="proc", timeout=20),
    C("hang-report-fifo-robot", f"report {REP} --robot pipe.urdf --out r", 2, err=("pipe.urdf", NOT_REGULAR), setup=(fifo("pipe.urdf"),), run="proc", timeout=20, absent=("r",)),
    C("hang-sweep-fifo-robot", f"sweep pd --samples 2 {SIM} --robot pipe.urdf --no-plot --out s", 2, err=("pipe.urdf", NOT_REGULAR), setup=(fifo("pipe.urdf"),), run="proc", timeout=20),
    C("hang-animate-from-fifo", "animate --from run.npz --html a.html", 2, err=("run.npz", NOT_REGULAR), setup=(fifo("run.npz"),), run="proc", timeout=20),
    C("hang-simulate-law-file-fifo", f"simulate law.py:Law {SIM}", 2, err=("law.py", NOT_REGULAR), setup=(fifo("law.py"),), run="proc", timeout=20),
    C("hang-info-dev-zero", "info --robot /dev/zero", 2, err=("/dev/zero", NOT_REGULAR), run="proc", memory=3 * GiB, timeout=20),
    C("hang-info-dev-urandom", "info --robot /dev/urandom", 2, err=("/dev/urandom", NOT_REGULAR), run="proc", memory=3 * GiB, timeout=20),
    C("hang-info-dev-null", "info --robot /dev/null", 2, err=("/dev/null", NOT_REGULAR), run="proc", timeout=20),
    C("hang-simulate-device-node-robot", f"simulate pd {SIM} --robot zero.urdf", 2, err=("zero.urdf", NOT_REGULAR), setup=(device("zero.urdf", "zero"),), run="proc", memory=3 * GiB, timeout=20),
    C("hang-animate-from-dev-zero", "animate --from /dev/zero --html a.html", 2, err=("/dev/zero", NOT_REGULAR), run="proc", memory=3 * GiB, timeout=20),
    C("hang-info-stdin-pipe", "info --robot /dev/stdin", 2, err=("/dev/stdin", NOT_REGULAR), run="stdin-pipe", timeout=20),
    C("hang-animate-from-stdin-pipe", "animate --from /dev/stdin --html a.html", 2, err=("/dev/stdin", NOT_REGULAR), run="stdin-pipe", timeout=20),
    C("hang-info-directory-robot", "info --robot arm.urdf", 2, err=("arm.urdf", "directory"), setup=(folder("arm.urdf"),)),
    C("hang-animate-from-directory", "animate --from run.npz --html a.html", 2, err=("run.npz", "directory"), setup=(folder("run.npz"),)),
    C("hang-info-socket-robot", "info --robot sock.urdf", 2, err=("sock.urdf", NOT_REGULAR + "|socket"), setup=(unix_socket("sock.urdf"),)),
    # -- endless or huge documents
    C("hang-info-oversize-urdf", "info --robot big.urdf", 2, err=("big.urdf", "bytes|MB|MiB"), setup=(blob("big.urdf", oversize),), note="1 MiB over the loader's size bound (32 MiB if it has none)"),
    C("hang-simulate-oversize-urdf", f"simulate pd {SIM} --robot big.urdf", 2, err=("big.urdf", "bytes|MB|MiB"), setup=(blob("big.urdf", oversize),)),
    C("hang-info-many-links", "info --robot chain.urdf", 2, err=("chain.urdf", "links"), setup=(blob("chain.urdf", many_links),)),
    C("hang-info-deep-nesting", "info --robot deep.urdf", (0, 2), err=("deep.urdf",), setup=(blob("deep.urdf", deep_nesting),), run="proc", timeout=30, note="100 000 nested unknown elements: ignoring them or refusing are both sound; crashing is not"),
    C("hang-animate-from-huge-header", "animate --from big.npz --html a.html", 2, err=("big.npz",), setup=(blob("big.npz", npz_huge_header),), run="proc", memory=3 * GiB, timeout=30),
    C("hang-animate-from-zip-bomb", "animate --from bomb.npz --html a.html", 2, err=("bomb.npz",), setup=(blob("bomb.npz", npz_bomb),), run="proc", memory=2 * GiB, timeout=60, note="4 MB that inflate to 4 GiB: the loader must bound what it inflates, not only the file size"),
    # -- counts and sizes bounded by argparse or the library
    C("hang-report-workers-1000000", f"report {REP} --workers 1000000 --out r", 2, err=("1000000", str(MAX_WORKERS))),
    C("hang-report-workers-0", f"report {REP} --workers 0 --out r", 2, err=("0", str(MAX_WORKERS))),
    C("hang-report-workers-negative", f"report {REP} --workers -1 --out r", 2, err=("-1",)),
    C("hang-report-workers-fraction", f"report {REP} --workers 2.5 --out r", 2, err=("2.5",)),
    C("hang-report-workers-exponent", f"report {REP} --workers 1e3 --out r", 2, err=("1e3",)),
    C("hang-sweep-threads-0", f"sweep pd --samples 2 {SIM} --threads 0", 2, err=("0", "256")),
    C("hang-sweep-threads-100000", f"sweep pd --samples 2 {SIM} --threads 100000", 2, err=("100000", "256")),
    C("hang-sweep-chunk-0", f"sweep pd --samples 2 {SIM} --chunk 0", 2, err=("0", str(MAX_CHUNK))),
    C("hang-sweep-chunk-too-big", f"sweep pd --samples 2 {SIM} --chunk {MAX_CHUNK * 100}", 2, err=(str(MAX_CHUNK * 100), str(MAX_CHUNK))),
    C("hang-sweep-samples-1e9", f"sweep pd --samples 1000000000 {SIM}", 2, err=("1000000000", str(MAX_SAMPLES))),
    C("hang-sweep-samples-0", f"sweep pd --samples 0 {SIM}", 2, err=("0", str(MAX_SAMPLES))),
    C("hang-sweep-samples-negative", f"sweep pd --samples -5 {SIM}", 2, err=("-5",)),
    C("hang-sweep-samples-exponent", f"sweep pd --samples 1e3 {SIM}", 2, err=("1e3",)),
    C("hang-sweep-keep-trajectories-terabytes", f"sweep pd --samples {MAX_SAMPLES} --duration 10 --keep-trajectories --no-plot --out s", 2, err=("TB|GB|bytes|too large|recorded values",), run="proc", memory=4 * GiB, timeout=30, absent=("s",), note="judgement: ~5 TB of trajectories must be refused before the first run, not discovered by filling the disk"),
    C("hang-sweep-keep-trajectories-terabytes-small-chunks", f"sweep pd --samples {MAX_SAMPLES} --duration 10 --chunk 100 --keep-trajectories --no-plot --out s", 2, err=("TB|GB|bytes|too large|recorded values",), run="proc", memory=4 * GiB, timeout=15, absent=("s",), note="the same 5 TB in chunks of 100 runs: the bound is on the whole study, not on one chunk"),
    # -- simulated time and steps
    C("hang-simulate-adaptive-lambda-1e9", "simulate computed-torque --method adaptive --lambda 1e9 --duration 30", 1, err=("computed-torque", "t =", "collapsed|diverged|step"), timeout=60),
    C("hang-simulate-dt-1e-9", "simulate pd --dt 1e-9 --duration 30", 2, err=("1e-09|1e-9", str(MAX_STEPS))),
    C("hang-simulate-duration-1e300", "simulate pd --duration 1e300", 2, err=("1e300", f"{MAX_DURATION:g}")),
    C("hang-simulate-duration-max", f"simulate pd --duration {MAX_DURATION:g}", 2, err=(str(MAX_STEPS),)),
    C("hang-simulate-coarse-dt", f"simulate pd --duration {MAX_DURATION:g} --dt 1", (1, 2), err=("pd|dt",), timeout=60, note="10^6 steps of 1 s: the stiff loop diverges at once (exit 1 at the first steps) or is refused; it must not run for minutes"),
    C("hang-simulate-adaptive-long", "simulate pd --method adaptive --duration 1e5 --dt 1", (0, 1, 2), timeout=60, note="a long adaptive run on a coarse output grid: it must end or be refused within the timeout"),
    C("hang-sweep-duration-max", f"sweep pd --samples 2 --duration {MAX_DURATION:g}", 2, err=(str(MAX_STEPS),)),
    C("hang-compare-duration-max", f"compare pd --duration {MAX_DURATION:g} --no-plot --out c", 2, err=(str(MAX_STEPS),), absent=("c",)),
    C("hang-report-duration-max", f"report --no-limits-section --duration {MAX_DURATION:g} --workers 1 --no-animation --out r", 2, err=(str(MAX_STEPS),), absent=("r",)),
    C("hang-animate-duration-1e5", "animate pd --duration 1e5 --html a.html", 2, err=(str(MAX_STEPS),), absent=("a.html",)),
    C("hang-animate-port-70000", f"animate pd {SIM} --no-browser --port 70000", 2, err=("70000", "65535")),
    C("hang-simulate-trajectory-file-fifo", f"simulate pd {SIM} --trajectory via.json", 2, err=("via.json", NOT_REGULAR), setup=(fifo("via.json"),), run="proc", timeout=20),
    C("hang-trajectory-file-dev-zero", "trajectory --trajectory /dev/zero", 2, err=("/dev/zero", NOT_REGULAR), run="proc", memory=3 * GiB, timeout=20),
    C("hang-trajectory-file-stdin-pipe", "trajectory --trajectory /dev/stdin", 2, err=("/dev/stdin", NOT_REGULAR), run="stdin-pipe", timeout=20),
    C("hang-trajectory-file-oversize", "trajectory --trajectory via.json", 2, err=("via.json", "bytes|MB|MiB"), setup=(via("via.json", VIA_JSON[:-2] + " " * (MAX_TRAJECTORY_BYTES + 2**20) + "}\n"),)),
    C("hang-trajectory-file-many-via-points", "trajectory --trajectory via.json", 2, err=("times", f"{MAX_VIA_POINTS}|too many"), setup=(via("via.json", json_file({"times": list(range(200)), "joints": [[0.0, 0.0]] * 200})),))
]


# == 4. Tracebacks instead of one-line errors ========================================================
# Every way the environment can say no — permissions, a full disk, a closed or full stdout,
# files that are not what their name says, a law that fails — must come out as one line.
NPZ_BAD = {
    "empty": blob("bad.npz", b""),
    "garbage": blob("bad.npz", garbage(4096)),
    "text": text("bad.npz", "hello\n"),
    "plain-zip": blob("bad.npz", zip_of([("readme.txt", 0, zlib.crc32(b"hi\n"), b"hi\n", 3)])),
    "missing-keys": blob("bad.npz", npz_arrays(a=np.zeros(3))),
    "pickled": blob("bad.npz", npz_pickled)
}
NPZ_EDIT = {
    "q-one-dimensional": {"q": lambda q: q[:, 0]},
    "q-nan": {"q": lambda q: np.where(np.arange(q.shape[0])[:, None] == 7, np.nan, q)},
    "t-decreasing": {"t": lambda t: t[::-1]},
    "q-three-joints": {"q": lambda q: np.concatenate([q, q[:, :1]], axis=1)},
    "q-shorter-than-t": {"q": lambda q: q[:10]},
    "no-q-des": {"q_des": None}
}
STDOUT = {
    "info": "info",
    "controllers": "controllers",
    "fk": "fk 0.1 0.2",
    "simulate": f"simulate pd {SIM}",
    "sweep": f"sweep pd --samples 2 {SIM} --no-plot --out s"
}
TRACEBACK = [
    # -- read-only folders, as a user without root meets them (CAP_DAC_OVERRIDE dropped)
    C("traceback-simulate-save-read-only", f"simulate pd {SIM} --save ro/run.npz", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/run.npz",)),
    C("traceback-simulate-plot-read-only", f"simulate pd {SIM} --plot ro/figs", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/figs",)),
    C("traceback-trajectory-plot-read-only", "trajectory --plot ro", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv"),
    C("traceback-animate-html-read-only", f"animate pd {SIM} --html ro/a.html", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/a.html",)),
    C("traceback-compare-out-read-only", f"compare pd {SIM} --no-plot --out ro/c", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/c",)),
    C("traceback-sweep-out-read-only", f"sweep pd --samples 2 {SIM} --no-plot --out ro/s", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/s",)),
    C("traceback-report-out-read-only", f"report {REP} --out ro/r", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/r",)),
    C("traceback-info-write-urdf-read-only", "info --payload 1 --write-urdf ro/heavy.urdf", 2, err=("ro", "Permission denied"), setup=RO, run="setpriv", absent=("ro/heavy.urdf",)),
    C("traceback-compare-out-is-read-only-folder", f"compare pd {SIM} --no-plot --out ro", 2, err=("ro", "Permission denied|read-only|not writable"), setup=RO, run="setpriv", note="judgement: an empty folder the user made read-only must not be swapped for a writable one"),
    C("traceback-compare-default-out-read-only-cwd", f"compare pd {SIM} --no-plot", 2, err=("Permission denied",), setup=RO, cwd="ro", run="setpriv"),
    C("traceback-info-unreadable-urdf", "info --robot secret.urdf", 2, err=("secret.urdf", "Permission denied|cannot be read"), setup=(twolink("secret.urdf"), chmod("secret.urdf", 0)), run="setpriv"),
    C("traceback-info-urdf-in-unsearchable-folder", "info --robot locked/arm.urdf", 2, err=("arm.urdf", "Permission denied"), setup=(twolink("locked/arm.urdf"), chmod("locked", 0)), run="setpriv"),
    C("traceback-animate-from-unreadable", "animate --from run.npz --html a.html", 2, err=("run.npz", "Permission denied|cannot be read"), setup=(SAVED, chmod("run.npz", 0)), run="setpriv"),
    C("traceback-simulate-unreadable-law", f"simulate law.py:Law {SIM}", 2, err=("law.py", "Permission denied"), setup=(text("law.py", "x = 1\n"), chmod("law.py", 0)), run="setpriv"),
    # -- a full disk (a 32 KiB tmpfs in a private mount namespace)
    C("traceback-simulate-save-full-disk", "simulate pd --duration 2 --save full/run.npz", 2, err=("run.npz", "No space left on device"), run="fullfs"),
    C("traceback-simulate-plot-full-disk", f"simulate pd {SIM} --plot full/figs", 2, err=("No space left on device",), run="fullfs"),
    C("traceback-trajectory-plot-full-disk", "trajectory --plot full/figs", 2, err=("No space left on device",), run="fullfs"),
    C("traceback-animate-html-full-disk", f"animate pd {SIM} --html full/a.html", 2, err=("a.html", "No space left on device"), run="fullfs"),
    C("traceback-compare-out-no-plot-full-disk", f"compare pd {SIM} --no-plot --out full/c", 2, err=("No space left on device",), run="fullfs-filled"),
    C("traceback-sweep-out-full-disk", f"sweep pd --samples 20 {SIM} --out full/s", 2, err=("No space left on device",), run="fullfs"),
    C("traceback-sweep-keep-trajectories-full-disk", f"sweep pd --samples 20 {SIM} --no-plot --keep-trajectories --out full/s", 2, err=("No space left on device",), run="fullfs"),
    C("traceback-report-out-full-disk", f"report {REP} --out full/r", 2, err=("No space left on device",), run="fullfs"),
    C("traceback-info-write-urdf-full-disk", "info --payload 1 --write-urdf full/heavy.urdf", 2, err=("heavy.urdf", "No space left on device"), run="fullfs-filled"),
    # -- stdout closed or full: non-zero, one line on stderr
    *(C(f"traceback-{name}-stdout-closed", argv, (1, 2), err=("stdout|output|Bad file descriptor",), run="stdout-closed", timeout=30) for name, argv in STDOUT.items()),
    *(C(f"traceback-{name}-stdout-full", argv, (1, 2), err=("No space left on device",), run="stdout-full", timeout=30) for name, argv in STDOUT.items()),
    C("traceback-info-stderr-closed", "info --robot nosuch", 2, run="stderr-closed"),
    C("traceback-simulate-stderr-closed-argparse", "simulate pd --dt 0", 2, run="stderr-closed"),
    C("traceback-simulate-stderr-closed-diverged", f"simulate computed-torque {SIM} --lambda 1e6 --no-step-check", 1, run="stderr-closed"),
    # -- runs that fail: exit 1 naming the law and the time
    C("traceback-report-lambda-1e6", "report --no-limits-section --duration 1 --workers 1 --no-animation --lambda 1e6 --no-step-check --out r", 1, err=("t =", "computed-torque|robust|adaptive"), exists=("r/index.html",), note="run anyway: the laws without λ finish, their results are written", timeout=240),
    C("traceback-report-lambda-1e6-workers-2", "report --no-limits-section --duration 1 --workers 2 --no-animation --lambda 1e6 --no-step-check --out r", 1, err=("t =", "computed-torque|robust|adaptive"), run="proc", exists=("r/index.html",), timeout=240),
    C("traceback-report-lambda-1e6-refused", "report --no-limits-section --duration 1 --workers 1 --no-animation --lambda 1e6 --out r", 2, err=("computed-torque: --dt = 0.001 is invalid", "lam [1/s]"), absent=("r",), note="the step check refuses λ = 1e6 before any run (issue 50)"),
    C("traceback-compare-lambda-1e6", f"compare {SIM} --no-plot --lambda 1e6 --no-step-check --out c", 1, err=("t =", "computed-torque|robust|adaptive"), exists=("c/comparison.csv",), note="run anyway: pd finishes, its row is written"),
    C("traceback-compare-lambda-1e6-refused", f"compare {SIM} --no-plot --lambda 1e6 --out c", 2, err=("computed-torque: --dt = 0.001 is invalid", "at most 2.7e-06 s"), absent=("c",), note="the step check refuses every row before any runs"),
    C("traceback-sweep-lambda-1e6", f"sweep computed-torque --samples 3 {SIM} --lambda 1e6 --no-plot --out s", 2, err=(STEP_REFUSED,), absent=("s",), note="one λ for every run: refused as a single run's"),
    C("traceback-simulate-lambda-1e6", f"simulate computed-torque {SIM} --lambda 1e6", 2, err=("computed-torque", STEP_REFUSED)),
    C("traceback-simulate-lambda-1e6-run-anyway", f"simulate computed-torque {SIM} --lambda 1e6 --no-step-check", 1, err=("computed-torque", "t =")),
    C("traceback-animate-lambda-1e6", f"animate computed-torque {SIM} --lambda 1e6 --html a.html", 2, err=("computed-torque", STEP_REFUSED), absent=("a.html",)),
    C("traceback-simulate-law-raises", f"simulate {LAW}/raiser.py:Raiser {SIM}", 1, err=("corpus-raiser", "t =", "corpus boom")),
    C("traceback-simulate-law-nan-torque", f"simulate {LAW}/nan_torque.py:NanTorque {SIM}", 1, err=("corpus-bad-torque", "t =")),
    C("traceback-simulate-law-wrong-shape", f"simulate {LAW}/wrong_shape.py:WrongShape {SIM}", 1, err=("corpus-wrong-shape", "shape")),
    C("traceback-simulate-law-init-raises", f"simulate {LAW}/init_raises.py:InitRaises {SIM}", (1, 2), err=("corpus-init-raises|InitRaises", "ZeroDivisionError|division")),
    C("traceback-simulate-law-import-raises", f"simulate {LAW}/import_raises.py:Law {SIM}", 2, err=("import_raises.py", "ValueError")),
    C("traceback-simulate-law-syntax-error", f"simulate broken.py:Broken {SIM}", 2, err=("broken.py", "SyntaxError|syntax"), setup=(text("broken.py", "class Broken(\n    def compute(self):\n"),)),
    C("traceback-simulate-law-not-a-controller", f"simulate {LAW}/not_a_law.py:NotALaw {SIM}", 2, err=("NotALaw", "Controller")),
    C("traceback-simulate-law-no-such-class", f"simulate {LAW}/raiser.py:Nope {SIM}", 2, err=("Nope", "Raiser")),
    C("traceback-simulate-law-no-such-file", f"simulate nosuch.py:Law {SIM}", 2, err=("nosuch.py",)),
    C("traceback-simulate-law-module-attribute-not-a-class", f"simulate os:path {SIM}", 2, err=("os:path",)),
    C("traceback-simulate-law-no-such-module", f"simulate nosuchmodule_xyz:Law {SIM}", 2, err=("nosuchmodule_xyz",)),
    C("traceback-compare-law-raises", f"compare {LAW}/raiser.py:Raiser pd {SIM} --no-plot --out c", 1, err=("corpus-raiser", "t ="), exists=("c/comparison.csv",), note="pd's row is written"),
    C("traceback-sweep-law-raises", f"sweep {LAW}/raiser.py:Raiser --samples 2 {SIM} --no-plot --out s", 1, err=("corpus-raiser", "t ="), absent=("s",)),
    C("traceback-report-law-raises", f"report --no-limits-section --duration 1 --workers 1 --no-animation --controller {LAW}/raiser.py:Raiser --out r", 1, err=("corpus-raiser", "t ="), exists=("r/index.html",), note="the page says the law did not finish", timeout=240),
    C("traceback-animate-law-raises", f"animate {LAW}/raiser.py:Raiser {SIM} --html a.html", 1, err=("corpus-raiser", "t ="), absent=("a.html",)),
    # -- qp-osc: limits that cannot all hold (1 % of the effort cannot hold the Panda up within 1 % of its accelerations), a QP that stops mid-run
    C("traceback-simulate-qp-osc-limits-cannot-hold", f"simulate qp-osc --robot panda --gain limit_scale=0.01 --gain on_infeasible=fail {SIM}", 1, err=("qp-osc", "t =", "cannot all hold", "of joint")),
    C("traceback-compare-qp-osc-limits-cannot-hold", "compare osc qp-osc --robot panda --gain qp-osc.limit_scale=0.01 --gain qp-osc.on_infeasible=fail --duration 0.05 --no-plot --out c", 1, err=("qp-osc", "t =", "cannot all hold"), exists=("c/comparison.csv",), checks=(contains("c/comparison.md", "| osc |"),), note="osc's row is written"),
    C("traceback-report-qp-osc-limits-cannot-hold", "report --no-limits-section --robot panda --duration 0.2 --workers 1 --no-animation --no-identification --controller osc --controller qp-osc --gain qp-osc.limit_scale=0.01 --gain qp-osc.on_infeasible=fail --out r", 1, err=("qp-osc", "t =", "cannot all hold"), exists=("r/index.html",), checks=(contains("r/index.html", "cannot all hold"),), note="the page says qp-osc did not finish and why; osc's results are in it", timeout=240),
    C("traceback-simulate-qp-osc-cannot-hold-mid-run", "simulate qp-osc --robot panda --payload 3 --trajectory fold.toml --q0-offset 1.5 0 0 0 0 0 0 --gain limit_scale=0.25 --gain on_infeasible=fail --duration 0.5", 1, err=("qp-osc", "t = 0.", "cannot all hold", "of joint"), setup=(via("fold.toml", PANDA_FOLD),), note="a quarter of the effort brakes the arm's swing too late: the limits stop being satisfiable partway"),
    # -- saved results that are not
    *(C(f"traceback-animate-from-{name}", "animate --from bad.npz --html a.html", 2, err=("bad.npz",), setup=(step,), absent=("a.html",)) for name, step in NPZ_BAD.items()),
    C("traceback-animate-from-truncated", "animate --from run.npz --html a.html", 2, err=("run.npz",), setup=(SAVED, truncate("run.npz", 2000)), absent=("a.html",)),
    *(C(f"traceback-animate-from-{name}", "animate --from bad.npz --html a.html", 2, err=("bad.npz",), setup=(SAVED, blob("bad.npz", npz_from_saved("run.npz", **edit))), absent=("a.html",)) for name, edit in NPZ_EDIT.items()),
    C("traceback-animate-from-missing-file", "animate --from nosuch.npz --html a.html", 2, err=("nosuch.npz", "no such file|not found")),
    C("traceback-animate-from-valid", "animate --from run.npz --html a.html", 0, setup=(SAVED,), exists=("a.html",)),
    # -- meshes that cannot be found
    C("traceback-animate-html-missing-mesh", f"animate pd {SIM} --robot missing_mesh.urdf --html a.html", 2, err=("nothere.stl",), setup=(urdf("missing_mesh"),), absent=("a.html",)),
    C("traceback-animate-html-package-mesh", f"animate pd {SIM} --robot package_mesh.urdf --html a.html", 2, err=("nosuchpkg",), setup=(urdf("package_mesh"),), absent=("a.html",)),
    C("traceback-animate-from-missing-mesh", "animate --from run.npz --robot missing_mesh.urdf --html a.html", 2, err=("nothere.stl",), setup=(urdf("missing_mesh"), cli("simulate", "pd", "--duration", "0.5", "--robot", "missing_mesh.urdf", "--save", "run.npz")), absent=("a.html",)),
    C("traceback-animate-serve-missing-mesh", f"animate pd {SIM} --robot missing_mesh.urdf --no-browser", 2, err=("nothere.stl",), setup=(urdf("missing_mesh"),), run="proc", timeout=30),
    C("traceback-simulate-missing-mesh", f"simulate pd {SIM} --robot missing_mesh.urdf", 0, setup=(urdf("missing_mesh"),), note="a run needs no mesh"),
    # -- the live viewer's address
    C("traceback-animate-serve-port-in-use", f"animate pd {SIM} --no-browser --port {{port}}", 2, err=("{port}", "in use"), run="proc", timeout=30),
    C("traceback-animate-serve-bad-host", f"animate pd {SIM} --no-browser --host 999.0.0.1", 2, err=("999.0.0.1",), run="proc", timeout=30),
    C("traceback-animate-serve-empty-host", ("animate", "pd", "--duration", "0.5", "--no-browser", "--host", ""), 2, err=("host",), run="proc", timeout=30),
    # -- numbers and names argparse or the library refuses
    C("traceback-sweep-seed-negative", f"sweep pd --samples 2 {SIM} --seed -1", 2, err=("-1", ">= 0|0 to")),
    C("traceback-sweep-seed-2-64", f"sweep pd --samples 2 {SIM} --seed {2**64}", 2, err=(str(2**64),)),
    C("traceback-sweep-seed-text", f"sweep pd --samples 2 {SIM} --seed abc", 2, err=("abc",)),
    C("traceback-info-payload-text", "info --payload abc", 2, err=("abc",)),
    C("traceback-simulate-gain-no-equals", f"simulate pd {SIM} --gain kp", 2, err=("kp", "NAME=VALUE")),
    C("traceback-simulate-gain-empty-value", f"simulate pd {SIM} --gain kp=", 2, err=("kp",)),
    C("traceback-simulate-gain-text", f"simulate pd {SIM} --gain kp=abc", 2, err=("abc",)),
    C("traceback-simulate-gain-unknown", f"simulate pd {SIM} --gain zeta=3", 2, err=("zeta", "kp", "kd")),
    C("traceback-simulate-gain-negative", f"simulate pd {SIM} --gain kp=-5", 2, err=("-5", "> 0|positive")),
    C("traceback-simulate-gain-zero", f"simulate pd {SIM} --gain kd=0", 2, err=("kd", "> 0|positive")),
    C("traceback-simulate-gain-empty-entry", f"simulate pd {SIM} --gain kp=1,,2", 2, err=("kp",)),
    C("traceback-sweep-gain-reversed", f"sweep pd --samples 2 {SIM} --gain kp=400:100", 2, err=("400", "100")),
    C("traceback-sweep-gain-text", f"sweep pd --samples 2 {SIM} --gain kp=a:b", 2, err=("kp=a:b",)),
    C("traceback-sweep-gain-unknown", f"sweep pd --samples 2 {SIM} --gain zeta=1:2", 2, err=("zeta", "kp")),
    C("traceback-sweep-gain-index-out-of-range", f"sweep pd --samples 2 {SIM} --gain kp3=1:2 --no-plot --out s", 2, err=("kp3",)),
    C("traceback-sweep-gain-twice", f"sweep pd --samples 2 {SIM} --gain kp=1:2 --gain kp=3:4", 2, err=("kp", "once")),
    C("traceback-sweep-param-error-1", f"sweep pd --samples 2 {SIM} --param-error 1", 2, err=("1",)),
    C("traceback-sweep-q0-spread-negative", f"sweep pd --samples 2 {SIM} --q0-spread -1", 2, err=("-1",)),
    # -- usage errors: one line too
    C("traceback-no-command", "", 2, err=("required|command",)),
    C("traceback-unknown-command", "simulat pd", 2, err=("simulat",)),
    C("traceback-unknown-option", "info --bogus", 2, err=("--bogus",)),
    C("traceback-simulate-no-controller", "simulate", 2, err=("CONTROLLER|controller",)),
    C("traceback-fk-no-angles", "fk", 2, err=("Q",)),
    C("traceback-ik-one-coordinate", "ik 0.5", 2, err=("y",)),
    C("traceback-simulate-method-euler", f"simulate pd {SIM} --method euler", 2, err=("euler", "rk4")),
    C("traceback-sweep-no-samples", "sweep pd", 2, err=("--samples",)),
    C("traceback-simulate-option-missing-value", "simulate pd --duration", 2, err=("--duration",)),
    # -- odd characters in arguments
    C("traceback-info-nul-in-robot", ("info", "--robot", "arm\x00.urdf"), 2, err=("null|NUL|\\x00|\\0",)),
    C("traceback-simulate-nul-in-save", ("simulate", "pd", "--duration", "0.5", "--save", "run\x00.npz"), 2, err=("null|NUL|\\x00|\\0",)),
    C("traceback-compare-nul-in-out", ("compare", "pd", "--duration", "0.5", "--no-plot", "--out", "c\x00"), 2, err=("null|NUL|\\x00|\\0",)),
    C("traceback-simulate-nul-in-law", ("simulate", "law\x00.py:Law", "--duration", "0.5"), 2, err=("null|NUL|\\x00|\\0",)),
    C("traceback-info-non-utf8-missing-robot", (b"info", b"--robot", b"\xff.urdf"), 2, err=(".urdf",), run="proc"),
    C("traceback-info-non-utf8-robot", (b"info", b"--robot", b"\xff.urdf"), 0, setup=(twolink("\udcff.urdf"),), run="proc", note="a file name that is not UTF-8 is still a file name: print it escaped"),
    C("traceback-simulate-non-utf8-save", (b"simulate", b"pd", b"--duration", b"0.5", b"--save", b"\xff.npz"), 0, run="proc", exists=("\udcff.npz",)),
    C("traceback-info-long-robot-path", ("info", "--robot", "a" * 5000 + ".urdf"), 2, err=("too long|not found",)),
    C("traceback-simulate-save-long-name", ("simulate", "pd", "--duration", "0.5", "--save", "a" * 300 + ".npz"), 2, err=("too long",)),
    # -- trajectory files that are not
    C("traceback-trajectory-file-invalid-json", "trajectory --trajectory via.json", 2, err=("via.json", "JSON"), setup=(via("via.json", '{"times": [0, 1,\n'),)),
    C("traceback-trajectory-file-invalid-toml", "trajectory --trajectory via.toml", 2, err=("via.toml", "TOML"), setup=(via("via.toml", "times = [0, 1\njoints = \n"),)),
    C("traceback-trajectory-file-yaml", "trajectory --trajectory via.yaml", 2, err=("via.yaml", ".toml|.json"), setup=(via("via.yaml", "times: [0, 1]\n"),)),
    C("traceback-trajectory-file-not-utf8", "trajectory --trajectory via.json", 2, err=("via.json", "UTF-8"), setup=(blob("via.json", b'{"times": [0, 1], "joints": [[0, 0], [0.5, 0.3]], "note": "mod\xe8le"}\n'),)),
    C("traceback-trajectory-file-empty", "trajectory --trajectory via.json", 2, err=("via.json",), setup=(blob("via.json", b""),)),
    C("traceback-trajectory-file-top-level-list", "trajectory --trajectory via.json", 2, err=("via.json", "object|table"), setup=(via("via.json", "[0, 1, 2]\n"),)),
    C("traceback-trajectory-file-unknown-key", "trajectory --trajectory via.json", 2, err=("via.json", "time"), setup=(via("via.json", '{"time": [0, 1], "joints": [[0, 0], [0.5, 0.3]]}\n'),)),
    C("traceback-trajectory-file-no-times", "trajectory --trajectory via.json", 2, err=("times",), setup=(via("via.json", '{"joints": [[0, 0], [0.5, 0.3]]}\n'),)),
    C("traceback-trajectory-file-neither-joints-nor-positions", "trajectory --trajectory via.json", 2, err=("joints", "positions"), setup=(via("via.json", '{"times": [0, 1]}\n'),)),
    C("traceback-trajectory-file-both-joints-and-positions", "trajectory --trajectory via.json", 2, err=("joints", "positions"), setup=(via("via.json", '{"times": [0, 1], "joints": [[0, 0], [0.5, 0.3]], "positions": [[0.5, 0], [0.4, 0.1]]}\n'),)),
    C("traceback-trajectory-file-joints-three-wide", "trajectory --trajectory via.json", 2, err=("joints[0]", "2"), setup=(via("via.json", '{"times": [0, 1], "joints": [[0, 0, 0], [0.5, 0.3, 0]]}\n'),)),
    C("traceback-trajectory-file-times-not-increasing", "trajectory --trajectory via.json", 2, err=("times[2]", "increasing"), setup=(via("via.json", '{"times": [0, 1, 1], "joints": [[0, 0], [0.5, 0.3], [0, 0]]}\n'),)),
    C("traceback-trajectory-file-joint-beyond-limit", "trajectory --trajectory via.json", 2, err=("4", "3.14159"), setup=(via("via.json", '{"times": [0, 1, 2], "joints": [[0, 0], [4.0, 0.3], [0, 0]]}\n'),)),
    C("traceback-trajectory-file-position-out-of-reach", "trajectory --trajectory via.json", 2, err=("via.json|position", "reach"), setup=(via("via.json", '{"times": [0, 1], "positions": [[0.5, 0.0], [1.0, 0.0]]}\n'),)),
    C("traceback-trajectory-file-positions-four-wide", "trajectory --trajectory via.json", 2, err=("positions",), setup=(via("via.json", '{"times": [0, 1], "positions": [[0.5, 0, 0, 0], [0.4, 0.1, 0, 0]]}\n'),)),
    C("traceback-trajectory-file-seed-wrong-size", "trajectory --trajectory via.json", 2, err=("seed", "2"), setup=(via("via.json", '{"times": [0, 1], "positions": [[0.5, 0.0], [0.4, 0.1]], "seed": [0, 0, 0]}\n'),)),
    C("traceback-trajectory-file-period-shorter-than-span", "trajectory --trajectory via.json", 2, err=("period", "2"), setup=(via("via.json", '{"times": [0, 1, 2], "joints": [[0, 0], [0.5, 0.3], [0, 0]], "period": 1}\n'),)),
    C("traceback-trajectory-file-missing", "trajectory --trajectory nosuch.json", 2, err=("nosuch.json", "no such|not found")),
    C("traceback-trajectory-file-directory", "trajectory --trajectory via.json", 2, err=("via.json", "directory"), setup=(folder("via.json"),)),
    C("traceback-trajectory-file-unreadable", "trajectory --trajectory via.json", 2, err=("via.json", "Permission denied|cannot be read"), setup=(via("via.json", VIA_JSON), chmod("via.json", 0)), run="setpriv"),
    # -- Dask that cannot start its workers: one line naming the cause, none of distributed's tracebacks (issue 23)
    C("traceback-sweep-dask-nanny-cannot-spawn", f"sweep pd --samples 4 {SIM} --no-plot --workers 1 --out s", (1, 2), err=("LocalCluster did not start", "bogus"), env=(("DASK_DISTRIBUTED__WORKER__MULTIPROCESSING_METHOD", "bogus"),), run="proc", absent=("s",), timeout=120, note="a nanny that cannot spawn its worker: distributed logs its traceback unless the start-up is silenced"),
    C("traceback-sweep-dask-temporary-directory-missing", f"sweep pd --samples 4 {SIM} --no-plot --workers 1 --out s", (1, 2), err=("LocalCluster did not start", "/proc/nonexistent-dask-tmp"), env=(("DASK_TEMPORARY_DIRECTORY", "/proc/nonexistent-dask-tmp"),), run="proc", absent=("s",), timeout=120, note="a temporary folder that cannot be created (under /proc): distributed's 'Cluster closed without starting up' warning is not printed"),
]


# == 5. Silent inf/NaN ===============================================================================
# Huge and non-finite numbers: refused (2), or a divergence (1); a success prints no nan/inf.
NONFINITE = [
    C("nonfinite-info-payload-1e308", "info --payload 1e308", 2, err=("1e308", f"{MAX_PAYLOAD:g}")),
    C("nonfinite-info-payload-inf", "info --payload inf", 2, err=("inf", "finite")),
    C("nonfinite-info-payload-nan", "info --payload nan", 2, err=("nan", "finite")),
    C("nonfinite-info-payload-minus-inf", "info --payload -inf", 2, err=("-inf",)),
    C("nonfinite-info-payload-overflowing-literal", "info --payload 1e999", 2, err=("1e999",)),
    C("nonfinite-info-payload-max", f"info --payload {MAX_PAYLOAD:g}", 0),
    C("nonfinite-info-payload-subnormal", "info --payload 5e-324", 0),
    C("nonfinite-info-payload-minus-zero", "info --payload -0", 0),
    C("nonfinite-simulate-gain-kp-1e308", f"simulate pd {SIM} --gain kp=1e308", (1, 2), err=("kp|t =",)),
    C("nonfinite-simulate-gain-kd-1e308", f"simulate pd {SIM} --gain kd=1e308", (1, 2), err=("kd|t =",)),
    C("nonfinite-simulate-gain-kp-inf", f"simulate pd {SIM} --gain kp=inf", 2, err=("inf",)),
    C("nonfinite-simulate-gain-kp-nan", f"simulate pd {SIM} --gain kp=nan", 2, err=("nan",)),
    C("nonfinite-simulate-gain-per-joint-1e300", f"simulate pd {SIM} --gain kp=1e300,1", (1, 2), err=("kp|t =",)),
    C("nonfinite-simulate-gain-subnormal", f"simulate pd {SIM} --gain kp=1e-320", (0, 2)),
    C("nonfinite-simulate-adaptive-gamma-1e308", f"simulate adaptive {SIM} --gain gamma=1e308", (0, 1, 2), err=("gamma|t =",), note="gamma divides the update (Γ⁻¹): 1e308 freezes the estimates, a finite run"),
    C("nonfinite-simulate-adaptive-gamma-subnormal", f"simulate adaptive {SIM} --gain gamma=1e-320", (0, 1, 2), err=("gamma|t =",), note="1 / 1e-320 overflows to inf"),
    C("nonfinite-simulate-q0-offset-1e308", f"simulate pd {SIM} --q0-offset 1e308", 2, err=("1e308", f"{MAX_OFFSET:g}")),
    C("nonfinite-simulate-q0-offset-nan", f"simulate pd {SIM} --q0-offset nan", 2, err=("nan",)),
    C("nonfinite-simulate-q0-offset-inf", f"simulate pd {SIM} --q0-offset 0 inf", 2, err=("inf",)),
    C("nonfinite-simulate-q0-offset-max", f"simulate pd {SIM} --q0-offset {MAX_OFFSET:g}", (0, 1), warns=("passed its position range",), note="issue 36: a start that far off is past the ±π range: the run says so"),
    C("nonfinite-simulate-lambda-nan", f"simulate computed-torque {SIM} --lambda nan", 2, err=("nan",)),
    C("nonfinite-simulate-lambda-inf", f"simulate computed-torque {SIM} --lambda inf", 2, err=("inf",)),
    C("nonfinite-simulate-lambda-zero", f"simulate computed-torque {SIM} --lambda 0", 2, err=("0",)),
    C("nonfinite-simulate-lambda-negative", f"simulate computed-torque {SIM} --lambda -1", 2, err=("-1",)),
    C("nonfinite-simulate-lambda-max", f"simulate computed-torque {SIM} --lambda 1e12", 2, err=(STEP_REFUSED,)),
    C("nonfinite-simulate-adaptive-lambda-max", f"simulate adaptive {SIM} --lambda 1e12", 2, err=(STEP_REFUSED,)),
    C("nonfinite-simulate-lambda-max-run-anyway", f"simulate computed-torque {SIM} --lambda 1e12 --no-step-check", (0, 1)),
    C("nonfinite-simulate-dt-nan", f"simulate pd {SIM} --dt nan", 2, err=("nan",)),
    C("nonfinite-simulate-duration-nan", "simulate pd --duration nan", 2, err=("nan",)),
    C("nonfinite-simulate-duration-inf", "simulate pd --duration inf", 2, err=("inf",)),
    C("nonfinite-simulate-duration-negative", "simulate pd --duration -1", 2, err=("-1",)),
    C("nonfinite-simulate-duration-zero", "simulate pd --duration 0", 2, err=("0",)),
    C("nonfinite-simulate-control-period-nan", f"simulate pd {SIM} --control-period nan", 2, err=("nan",)),
    C("nonfinite-simulate-friction-smoothing-nan", f"simulate adaptive-friction {SIM} --friction-smoothing nan", 2, err=("nan",)),
    C("nonfinite-simulate-friction-smoothing-inf", f"simulate adaptive-friction {SIM} --friction-smoothing inf", 2, err=("inf",)),
    C("nonfinite-simulate-friction-smoothing-negative", f"simulate adaptive-friction {SIM} --friction-smoothing -1", 2, err=("-1",)),
    C("nonfinite-simulate-friction-smoothing-max", f"simulate adaptive-friction {SIM} --friction-smoothing 1000", 0),
    C("nonfinite-fk-nan", "fk nan 0", 2, err=("nan",)),
    C("nonfinite-fk-inf", "fk 0 inf", 2, err=("inf",)),
    C("nonfinite-fk-overflowing-literal", "fk 1e999 0", 2, err=("1e999",)),
    C("nonfinite-fk-1e308", "fk 1e308 -1e308 --json", 0, checks=(strict_json(),)),
    C("nonfinite-ik-1e308", "ik 1e308 1e308", 2, err=("1e+308|1e308",)),
    C("nonfinite-ik-nan", "ik nan 0", 2, err=("nan",)),
    C("nonfinite-sweep-gain-1e308", f"sweep pd --samples 3 {SIM} --gain kp=1:1e308 --no-plot --out s", (0, 1, 2), checks=(finite_file("s/summary.json"), finite_file("s/runs.csv"))),
    C("nonfinite-sweep-param-error-max", f"sweep pd --samples 3 {SIM} --param-error 0.999999 --no-plot --out s", 0),
    C("nonfinite-sweep-q0-spread-max", f"sweep pd --samples 3 {SIM} --q0-spread {MAX_OFFSET:g} --no-plot --out s", (0, 1), checks=(finite_file("s/summary.json"),)),
    C("nonfinite-sweep-lambda-nan", f"sweep computed-torque --samples 2 {SIM} --lambda nan", 2, err=("nan",)),
    C("nonfinite-info-huge-inertia", "info --robot huge_inertia.urdf", (0, 2), err=("huge_inertia.urdf",), setup=(urdf("huge_inertia"),)),
    C("nonfinite-info-huge-inertia-json", "info --robot huge_inertia.urdf --json", (0, 2), setup=(urdf("huge_inertia"),), checks=(strict_json(),)),
    C("nonfinite-trajectory-huge-inertia", "trajectory --robot huge_inertia.urdf", (0, 2), setup=(urdf("huge_inertia"),)),
    C("nonfinite-simulate-huge-inertia", f"simulate pd {SIM} --robot huge_inertia.urdf", (0, 1, 2), setup=(urdf("huge_inertia"),)),
    C("nonfinite-simulate-adaptive-huge-inertia", f"simulate adaptive {SIM} --robot huge_inertia.urdf", (0, 1, 2), setup=(urdf("huge_inertia"),)),
    C("nonfinite-info-huge-mass", "info --robot huge_mass.urdf", (0, 2), setup=(urdf("huge_mass"),)),
    C("nonfinite-trajectory-huge-mass", "trajectory --robot huge_mass.urdf", (0, 2), setup=(urdf("huge_mass"),)),
    C("nonfinite-simulate-huge-mass", f"simulate pd {SIM} --robot huge_mass.urdf", (0, 1, 2), setup=(urdf("huge_mass"),)),
    C("nonfinite-info-huge-mass-payload", f"info --robot huge_mass.urdf --payload {MAX_PAYLOAD:g} --json", (0, 2), setup=(urdf("huge_mass"),), checks=(strict_json(),)),
    C("nonfinite-simulate-tiny-inertia", f"simulate pd {SIM} --robot tiny_inertia.urdf", (1, 2), setup=(urdf("tiny_inertia"),)),
    C("nonfinite-info-no-limits", "info --robot no_limits.urdf", 0, out=("no limit|none",), setup=(urdf("no_limits"),)),
    C("nonfinite-info-no-limits-json", "info --robot no_limits.urdf --json", 0, setup=(urdf("no_limits"),), checks=(strict_json(),)),
    C("nonfinite-simulate-no-limits-json", f"simulate pd {SIM} --robot no_limits.urdf --json", 0, setup=(urdf("no_limits"),), checks=(strict_json(),)),
    C("nonfinite-simulate-no-limits-saturate", f"simulate pd {SIM} --robot no_limits.urdf --saturate", 2, err=("--saturate", "effort limits"), setup=(urdf("no_limits"),), note="issue 30: --saturate would clip nothing without effort limits: refused rather than ignored"),
    C("nonfinite-trajectory-no-limits", "trajectory --robot no_limits.urdf", 0, setup=(urdf("no_limits"),)),
    C("nonfinite-trajectory-no-limits-json", "trajectory --robot no_limits.urdf --json", 0, setup=(urdf("no_limits"),), checks=(strict_json(),)),
    C("nonfinite-compare-no-limits-json", f"compare pd {SIM} --robot no_limits.urdf --no-plot --json --out c", 0, setup=(urdf("no_limits"),), checks=(strict_json(),)),
    C("nonfinite-sweep-no-limits", f"sweep pd --samples 2 {SIM} --robot no_limits.urdf --no-plot --out s", 0, setup=(urdf("no_limits"),), checks=(finite_file("s/summary.json"),)),
    C("nonfinite-report-lambda-nan", f"report {REP} --lambda nan --out r", 2, err=("nan",)),
    C("nonfinite-report-payload-inf", f"report {REP} --payload inf --out r", 2, err=("inf",)),
    C("nonfinite-compare-duration-inf", "compare pd --duration inf --no-plot --out c", 2, err=("inf",)),
    C("nonfinite-animate-lambda-nan", f"animate computed-torque {SIM} --lambda nan --html a.html", 2, err=("nan",)),
    C("nonfinite-trajectory-file-json-nan", "trajectory --trajectory via.json", 2, err=("times", "finite|nan"), setup=(via("via.json", '{"times": [0, NaN], "joints": [[0, 0], [0.5, 0.3]]}\n'),), note="Python's json reads NaN and Infinity, which JSON does not have"),
    C("nonfinite-trajectory-file-json-infinity", "trajectory --trajectory via.json", 2, err=("joints", "finite|inf"), setup=(via("via.json", '{"times": [0, 1], "joints": [[0, 0], [Infinity, 0.3]]}\n'),)),
    C("nonfinite-trajectory-file-json-overflow", "trajectory --trajectory via.json", 2, err=("joints", "finite|inf|1e400"), setup=(via("via.json", '{"times": [0, 1], "joints": [[0, 0], [1e400, 0.3]]}\n'),)),
    C("nonfinite-trajectory-file-toml-nan", "trajectory --trajectory via.toml", 2, err=("joints", "finite|nan"), setup=(via("via.toml", "times = [0, 1]\njoints = [[0, 0], [nan, 0.3]]\n"),)),
    C("nonfinite-trajectory-file-toml-period-inf", "trajectory --trajectory via.toml", 2, err=("period", "inf|finite"), setup=(via("via.toml", "times = [0, 1]\njoints = [[0, 0], [0.5, 0.3]]\nperiod = inf\n"),)),
    C("nonfinite-trajectory-file-joints-1e308", "trajectory --trajectory via.json", 2, err=("1e+308|1e308", "3.14159"), setup=(via("via.json", '{"times": [0, 1], "joints": [[0, 0], [1e308, 0.3]]}\n'),)),
    C("nonfinite-trajectory-file-times-1e308", "trajectory --trajectory via.json", (0, 2), err=("times|period",), setup=(via("via.json", '{"times": [0, 1e308], "joints": [[0, 0], [0.5, 0.3]]}\n'),))
]


# == 6. Unclear messages =============================================================================
# What works must work; what fails must name the value and what was expected.
MALFORMED = {
    # name: (substitutions in twolink.urdf, words the message must contain)
    "negative-mass": ((('<mass value="10.0"/>', '<mass value="-1"/>'),), ("link1", "-1")),
    "mass-text": ((('<mass value="10.0"/>', '<mass value="abc"/>'),), ("link1", "abc")),
    "mass-nan": ((('<mass value="10.0"/>', '<mass value="nan"/>'),), ("link1", "nan")),
    "mass-with-unit": ((('<mass value="10.0"/>', '<mass value="10kg"/>'),), ("10kg",)),
    "mass-decimal-comma": ((('<mass value="10.0"/>', '<mass value="10,0"/>'),), ("10,0",)),
    "mass-xacro-unexpanded": ((('<mass value="10.0"/>', '<mass value="${m1}"/>'),), ("${m1}",)),
    "inertia-not-positive-definite": ((('ixy="0"', 'ixy="5"'),), ("link1", "positive semidefinite")),
    "inertia-triangle": ((('ixx="1.689" ixy="0" ixz="0" iyy="1.689"', 'ixx="0.1" ixy="0" ixz="0" iyy="0.1"'),), ("link1", "triangle")),
    "inertia-missing-attribute": ((('izz="1.689"', ""),), ("link1", "izz")),
    "zero-axis": ((('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'),), ("joint1", "axis")),
    "unknown-joint-type": ((('type="revolute"', 'type="hinge"'),), ("joint1", "hinge")),
    "duplicate-link": ((('<link name="link2">', '<link name="link1">'),), ("link1",)),
    "undeclared-parent": ((('<parent link="link1"/>', '<parent link="linkX"/>'),), ("linkX",)),
    "cycle": ((('<parent link="base_link"/>', '<parent link="ee_link"/>'),), ("root|cycle",)),
    "lower-above-upper": ((('lower="-3.14159265" upper="3.14159265" effort="240"', 'lower="1" upper="-1" effort="240"'),), ("joint1", "lower")),
    "negative-effort": ((('effort="240"', 'effort="-1"'),), ("joint1", "effort")),
    "limit-without-effort": ((('effort="240" ', ""),), ("joint1", "effort")),
    "limit-without-velocity": ((('effort="240" velocity="10"', 'effort="240"'),), ("joint1", "velocity")),
    "origin-two-numbers": ((('<origin xyz="0.38 0 0" rpy="0 0 0"/>', '<origin xyz="0.38 0" rpy="0 0 0"/>'),), ("joint2", "xyz")),
    "origin-overflow": ((('<origin xyz="0.38 0 0" rpy="0 0 0"/>', '<origin xyz="1e999 0 0" rpy="0 0 0"/>'),), ("joint2", "1e999")),
    "root-not-robot": ((('<robot name="twolink">', '<html name="twolink">'), ("</robot>", "</html>")), ("html",)),
    "joint-without-name": ((('<joint name="joint2" type="revolute">', '<joint type="revolute">'),), ("joint", "name")),
    "robot-without-name": ((('<robot name="twolink">', "<robot>"),), ("robot", "name")),
    "joint-without-child": ((('<child link="link2"/>', ""),), ("joint2", "child"))
}
UNCLEAR = [
    # -- negative numbers are numbers
    C("unclear-fk-negative-exponent", "fk 0.1 -1e-3 --json", 0, checks=(fk_closed_form(0.1, -1e-3),)),
    C("unclear-fk-negative-both", "fk -1e-3 -2.5E+0 --json", 0, checks=(fk_closed_form(-1e-3, -2.5),)),
    C("unclear-fk-leading-dot", "fk -.5 .25 --json", 0, checks=(fk_closed_form(-0.5, 0.25),)),
    C("unclear-fk-negative-integers", "fk -1 -2 --json", 0, checks=(fk_closed_form(-1.0, -2.0),)),
    C("unclear-ik-negative-exponent", "ik 0.48 -1e-1 --json", 0, checks=(ik_reaches(None, 0.48, -0.1),)),
    C("unclear-simulate-negative-offsets", f"simulate pd {SIM} --q0-offset -1e-2 -.05", 0),
    # -- the number of joints
    C("unclear-fk-one-angle", "fk 0.1", 2, err=("2 joint", "0.1")),
    C("unclear-fk-three-angles", "fk 0.1 0.2 0.3", 2, err=("2 joint",)),
    C("unclear-fk-arm3", "fk 0.1 0.2 0.3 --robot arm3.urdf --json", 0, setup=(urdf("arm3"),)),
    C("unclear-fk-arm3-two-angles", "fk 0.1 0.2 --robot arm3.urdf", 2, err=("3 joint",), setup=(urdf("arm3"),)),
    C("unclear-info-arm3", "info --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-trajectory-arm3", "trajectory --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-simulate-arm3", f"simulate pd {SIM} --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-simulate-computed-torque-arm3", f"simulate computed-torque {SIM} --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-simulate-adaptive-arm3", f"simulate adaptive {SIM} --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-simulate-adaptive-friction-arm3", f"simulate adaptive-friction {SIM} --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-simulate-arm3-q0-offset-two", f"simulate pd {SIM} --robot arm3.urdf --q0-offset 0.1 0.2", 2, err=("3 joint|3 values|nv = 3", "0.1"), setup=(urdf("arm3"),)),
    C("unclear-simulate-arm3-q0-offset-one", f"simulate pd {SIM} --robot arm3.urdf --q0-offset 0.1", 0, setup=(urdf("arm3"),)),
    C("unclear-simulate-arm3-gain-two", f"simulate pd {SIM} --robot arm3.urdf --gain kp=100,200", 2, err=("kp", "3"), setup=(urdf("arm3"),)),
    C("unclear-compare-arm3", f"compare {SIM} --robot arm3.urdf --no-plot --out c", 0, setup=(urdf("arm3"),), not_err=("near a singularity",), note="the planar 3R's task is x and y; its home is chosen bent (issue 50), not its stretched middle of the ranges, where impedance passed near a singularity"),
    C("unclear-sweep-arm3", f"sweep pd --samples 3 {SIM} --robot arm3.urdf --no-plot --out s", 0, setup=(urdf("arm3"),)),
    C("unclear-animate-arm3", f"animate pd {SIM} --robot arm3.urdf --html a.html", 0, setup=(urdf("arm3"),), exists=("a.html",)),
    C("unclear-simulate-arm2", f"simulate computed-torque {SIM} --robot arm2.urdf", 0, setup=(urdf("arm2"),)),
    # -- massless moving links: refused at load naming the joint, not a divergence at t = 0.001 s
    C("unclear-info-massless-link", "info --robot massless_link.urdf", 2, err=("joint2|link2", "mass"), not_err=("diverged",), setup=(urdf("massless_link"),)),
    C("unclear-simulate-massless-link", f"simulate pd {SIM} --robot massless_link.urdf", 2, err=("joint2|link2", "mass"), not_err=("diverged",), setup=(urdf("massless_link"),)),
    C("unclear-fk-massless-link", "fk 0 0 --robot massless_link.urdf", 2, err=("joint2|link2", "mass"), setup=(urdf("massless_link"),)),
    C("unclear-info-massless-explicit", "info --robot massless_explicit.urdf", 2, err=("joint2|link2", "mass"), setup=(urdf("massless_explicit"),)),
    C("unclear-simulate-massless-with-child", f"simulate pd {SIM} --robot massless_with_child.urdf", 0, setup=(urdf("massless_with_child"),)),
    # -- encodings
    C("unclear-info-utf16", "info --robot utf16.urdf", 2, err=("utf16.urdf", "UTF-16|encoding"), setup=(blob("utf16.urdf", utf16(True)),)),
    C("unclear-info-utf16-no-declaration", "info --robot utf16.urdf", 2, err=("utf16.urdf", "UTF-16|encoding"), setup=(blob("utf16.urdf", utf16(False)),)),
    C("unclear-simulate-utf16", f"simulate pd {SIM} --robot utf16.urdf", 2, err=("UTF-16|encoding",), setup=(blob("utf16.urdf", utf16(True)),)),
    C("unclear-info-utf8-bom", "info --robot bom.urdf", 0, setup=(blob("bom.urdf", utf8_bom),)),
    C("unclear-info-crlf", "info --robot crlf.urdf", 0, setup=(blob("crlf.urdf", crlf),)),
    C("unclear-info-blank-line-before-declaration", "info --robot arm.urdf", (0, 2), err=("arm.urdf", "declaration|line"), setup=(twolink("arm.urdf", ('<?xml version="1.0"?>', '\n<?xml version="1.0"?>')),)),
    C("unclear-info-latin1", "info --robot latin1.urdf", (0, 2), err=("latin1.urdf", "encoding|ISO-8859-1|latin"), setup=(blob("latin1.urdf", lambda _: twolink_text_latin1()),)),
    # -- joints Pinocchio models with more than one coordinate
    C("unclear-info-continuous", "info --robot continuous.urdf", (0, 2), err=("continuous",), setup=(urdf("continuous"),), note="judgement: continuous joints are everyday URDF; if refused, the message must say 'continuous', not only nq != nv"),
    C("unclear-info-floating", "info --robot floating.urdf", 2, err=("floating",), setup=(urdf("floating"),)),
    C("unclear-info-planar", "info --robot planar_joint.urdf", 2, err=("planar",), setup=(urdf("planar_joint"),)),
    C("unclear-info-fixed-only", "info --robot fixed_only.urdf", 2, err=("moving joint|no moving|nv = 0",), setup=(urdf("fixed_only"),)),
    # -- URDFs that are not sound: one line naming the element and what was expected
    *(C(f"unclear-info-urdf-{name}", "info --robot arm.urdf", 2, err=("arm.urdf", *words), setup=(twolink("arm.urdf", *subs),)) for name, (subs, words) in MALFORMED.items()),
    C("unclear-info-urdf-truncated", "info --robot arm.urdf", 2, err=("arm.urdf", "line"), setup=(twolink("arm.urdf"), truncate("arm.urdf", 1500))),
    C("unclear-info-urdf-empty", "info --robot arm.urdf", 2, err=("arm.urdf",), setup=(blob("arm.urdf", b""),)),
    C("unclear-info-urdf-garbage", "info --robot arm.urdf", 2, err=("arm.urdf",), setup=(blob("arm.urdf", garbage(2048)),)),
    C("unclear-info-urdf-no-links", "info --robot arm.urdf", 2, err=("arm.urdf", "link"), setup=(text("arm.urdf", '<?xml version="1.0"?>\n<robot name="x"/>\n'),)),
    C("unclear-info-urdf-gazebo-extension", "info --robot arm.urdf", 0, setup=(twolink("arm.urdf", ("</robot>", '  <gazebo reference="link1"><material>Gazebo/Blue</material></gazebo>\n</robot>')),)),
    C("unclear-info-urdf-mimic", "info --robot arm.urdf", (0, 2), err=("mimic",), setup=(twolink("arm.urdf", ('<child link="link2"/>', '<child link="link2"/>\n    <mimic joint="joint1" multiplier="1" offset="0"/>')),)),
    # -- names
    C("unclear-info-unknown-robot", "info --robot twolnk", 2, err=("twolnk", "twolink")),
    C("unclear-info-robot-case", "info --robot TWOLINK", 2, err=("TWOLINK", "twolink")),
    C("unclear-info-robot-dash", "info --robot -", 2, err=("twolink",)),
    C("unclear-info-robot-empty", ("info", "--robot", ""), 2, err=("twolink|empty",)),
    C("unclear-info-missing-urdf", "info --robot nosuch.urdf", 2, err=("nosuch.urdf", "not found|no such")),
    C("unclear-info-robot-dir", "info --robot ./", 2, err=("directory",)),
    C("unclear-simulate-unknown-law", f"simulate nosuchlaw {SIM}", 2, err=("nosuchlaw", "pd", "adaptive")),
    C("unclear-simulate-law-case", f"simulate PD {SIM}", 2, err=("PD", "pd")),
    C("unclear-simulate-law-empty", ("simulate", "", "--duration", "0.5"), 2, err=("law|controller",)),
    C("unclear-compare-law-twice", f"compare pd pd {SIM} --no-plot --out c", 2, err=("pd", "once"), absent=("c",)),
    C("unclear-report-law-twice", "report --no-limits-section --duration 1 --workers 1 --no-animation --controller pd --controller pd --out r", 2, err=("pd", "once"), absent=("r",)),
    # -- options that need others
    C("unclear-info-write-urdf-no-payload", "info --write-urdf heavy.urdf", 2, err=("--payload",), absent=("heavy.urdf",)),
    C("unclear-animate-nothing-to-show", "animate --html a.html", 2, err=("--from", "controller|CONTROLLER"), absent=("a.html",)),
    C("unclear-simulate-dt-over-duration", "simulate pd --duration 0.5 --dt 1", 2, err=("dt", "0.5")),
    C("unclear-simulate-adaptive-friction-exact-sign", f"simulate adaptive-friction {SIM} --method adaptive --friction-smoothing 0", 2, err=("friction-smoothing|friction_smoothing|friction.smoothing",)),
    C("unclear-ik-out-of-reach", "ik 0.7 0", 2, err=("0.7", "0.62")),
    C("unclear-ik-inside-hole", "ik 0 0", 2, err=("0.14",)),
    # -- what must simply work
    C("unclear-robots", "robots --json", 0, out=("twolink",), checks=(strict_json(),)),
    C("unclear-controllers", "controllers", 0, out=("pd", "adaptive"), run="proc", note="a real process: in this one the corpus's own laws are registered"),
    C("unclear-controllers-json", "controllers --json", 0, checks=(strict_json(),), run="proc"),
    C("unclear-help", "--help", 0, out=("simulate",)),
    C("unclear-simulate-help", "simulate --help", 0, out=("--duration",)),
    C("unclear-simulate-user-law-example", f"simulate examples/sliding_mode.py:SlidingMode {SIM}", 0, cwd="repo", setup=(symlink("repo", str(__import__("pathlib").Path(__file__).resolve().parents[2])),), note="the tutorial's law, run from the repository"),
    C("unclear-info-missing-mesh", "info --robot missing_mesh.urdf", 0, setup=(urdf("missing_mesh"),)),
    C("unclear-report-animation-twolink", "report --no-limits-section --duration 1 --workers 1 --controller pd --out r", 0, exists=("r/index.html", "r/animation.html"), checks=(contains("r/results.json", '"saturate": false'),)),
    # -- the catalog's other robots and the newer options
    C("unclear-info-friction", "info --friction --json", 0, checks=(strict_json(),)),
    C("unclear-info-friction-arm3", "info --friction --robot arm3.urdf", 0, setup=(urdf("arm3"),)),
    C("unclear-fk-ur5", "fk 0 -1.57 1.57 -1.57 -1.57 0 --robot ur5 --json", 0, checks=(strict_json(),)),
    C("unclear-fk-ur5-two-angles", "fk 0 0 --robot ur5", 2, err=("6 joint",)),
    C("unclear-simulate-ur5", "simulate pd --duration 0.2 --robot ur5", 0),
    C("unclear-simulate-panda-computed-torque", "simulate computed-torque --duration 0.2 --robot panda", 0),
    C("unclear-ik-seed-wrong-size", "ik 0.48 -0.1 --seed 0 0 0", 2, err=("--seed", "2")),
    C("unclear-ik-seed-nan", "ik 0.48 -0.1 --seed nan 0", 2, err=("nan",))
]


def twolink_text_latin1() -> bytes:
    """The twolink declared ISO-8859-1 with a Latin-1 comment (``é`` as one byte)."""
    import twolink_pin

    body = twolink_pin.twolink_urdf_path().read_text(encoding="utf-8")
    body = body.replace(
        '<?xml version="1.0"?>', '<?xml version="1.0" encoding="ISO-8859-1"?>\n<!-- modèle -->', 1
    )
    return body.encode("latin-1", errors="replace")


# == 7. Interrupts ===================================================================================
# SIGINT (Ctrl-C: to the whole process group) and SIGTERM (kill: to the parent only) on a
# running command: it ends within 5 s with 130 (SIGTERM: 130, 143 or death by the signal,
# as long as it cleans up), leaves no staging folder, no partial file, no worker process.
TERM_EXITS = 143
INTERRUPT = [
    C("interrupt-report-sigterm", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", TERM_EXITS, run="signal", signal=(SIGTERM, "running", "parent"), absent=("r",), err=("terminated",)),
    C("interrupt-report-sigint", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("r",)),
    C("interrupt-report-sigint-parent-only", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "parent"), absent=("r",)),
    C("interrupt-report-workers-1-sigterm", "report --no-limits-section --workers 1 --duration 30 --no-animation --out r", TERM_EXITS, run="signal", signal=(SIGTERM, "running", "parent"), absent=("r",), err=("terminated",)),
    C("interrupt-report-workers-1-sigint", "report --no-limits-section --workers 1 --duration 30 --no-animation --out r", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("r",)),
    C("interrupt-report-own-folder-sigint", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), setup=(cli("report", *REP.split(), "--out", "r"),), exists=("r/index.html",), note="the previous report stays whole"),
    C("interrupt-report-own-folder-sigterm", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", TERM_EXITS, run="signal", signal=(SIGTERM, "running", "parent"), setup=(cli("report", *REP.split(), "--out", "r"),), exists=("r/index.html",), err=("terminated",)),
    C("interrupt-sweep-sigint", "sweep pd --samples 20000 --duration 30 --out s", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("s",)),
    C("interrupt-sweep-sigterm", "sweep pd --samples 20000 --duration 30 --out s", TERM_EXITS, run="signal", signal=(SIGTERM, "running", "parent"), absent=("s",), err=("terminated",)),
    C("interrupt-simulate-sigint", "simulate adaptive --duration 1000 --save run.npz", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("run.npz",)),
    C("interrupt-simulate-sigterm", "simulate adaptive --duration 1000 --save run.npz", TERM_EXITS, run="signal", signal=(SIGTERM, "running", "parent"), absent=("run.npz",), err=("terminated",)),
    C("interrupt-compare-sigint", "compare --duration 300 --out c", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("c",)),
    C("interrupt-compare-sigterm", "compare --duration 300 --out c", TERM_EXITS, run="signal", signal=(SIGTERM, "running", "parent"), absent=("c",), err=("terminated",)),
    C("interrupt-animate-simulating-sigint", "animate adaptive --duration 1000 --html a.html", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("a.html",)),
    C("interrupt-animate-serve-sigint", f"animate pd {SIM} --no-browser", (0, 130), run="signal", signal=(SIGINT, "running", "group"), note="Ctrl-C is how the live viewer is meant to stop: 0 (or 130) and nothing left listening"),
    C("interrupt-animate-serve-sigterm", f"animate pd {SIM} --no-browser", (0, 130, 143), run="signal", signal=(SIGTERM, "running", "parent")),

    # while importing the package and parsing the arguments (the signal goes out at the entry's first statement)
    C("interrupt-simulate-importing-sigint", "simulate adaptive --duration 1000 --save run.npz", 130, err=("interrupted",), run="signal", signal=(SIGINT, "started", "group"), absent=("run.npz",)),
    C("interrupt-simulate-importing-sigterm", "simulate adaptive --duration 1000 --save run.npz", TERM_EXITS, err=("terminated",), run="signal", signal=(SIGTERM, "started", "parent"), absent=("run.npz",)),
    C("interrupt-fk-importing-sigint", "fk 0 0 --json", 130, err=("interrupted",), run="signal", signal=(SIGINT, "started", "group"), note="a command that takes no time still says 'interrupted' if Ctrl-C comes while it loads"),
    C("interrupt-report-importing-sigint", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", 130, err=("interrupted",), run="signal", signal=(SIGINT, "started", "group"), absent=("r",)),
    C("interrupt-sweep-importing-sigterm", "sweep pd --samples 20000 --duration 30 --out s", TERM_EXITS, err=("terminated",), run="signal", signal=(SIGTERM, "started", "parent"), absent=("s",)),
    C("interrupt-compare-parsed-sigint", "compare --duration 300 --out c", 130, err=("interrupted",), run="signal", signal=(SIGINT, "parsed", "group"), absent=("c",)),
    C("interrupt-sweep-parsed-sigint", "sweep pd --samples 20000 --duration 30 --out s", 130, err=("interrupted",), run="signal", signal=(SIGINT, "parsed", "group"), absent=("s",)),
    C("interrupt-report-parsed-sigterm", "report --no-limits-section --workers 2 --duration 30 --no-animation --out r", TERM_EXITS, err=("terminated",), run="signal", signal=(SIGTERM, "parsed", "parent"), absent=("r",)),
    C("interrupt-ik-parsed-sigterm", "ik 0.3 0.2 --json", (0, 143), run="signal", signal=(SIGTERM, "parsed", "parent"), note="ik may finish before the signal lands: its answer (exit 0) or 143, never a traceback"),
    # while writing: the signal comes when the output is being staged; the command may finish first
    C("interrupt-simulate-writing-sigint", "simulate pd --duration 20 --save run.npz", (0, 130), run="signal", signal=(SIGINT, "writing", "group"), checks=(whole_or_absent("run.npz"),)),
    C("interrupt-simulate-writing-sigterm", "simulate pd --duration 20 --save run.npz", (0, 143), run="signal", signal=(SIGTERM, "writing", "parent"), checks=(whole_or_absent("run.npz"),)),
    C("interrupt-report-own-folder-writing-sigint", "report --no-limits-section --workers 1 --duration 30 --no-animation --out r", 130, err=("interrupted",), run="signal", signal=(SIGINT, "writing", "group"), setup=(cli("report", *REP.split(), "--out", "r"),), exists=("r/index.html",), note="the report stages its folder before its runs: the previous report stays whole"),
]


# == 8. User code ====================================================================================
# A law or plug-in that misbehaves as user code can (laws/misbehaving.py): an error naming the
# law (exit 1, or 2 for a file that cannot be imported), nothing written, never a silent exit,
# a changed simulation, a corrupted --json or a hang. os._exit cannot be caught in-process
# (docs/reliability.md): no case for it.
MIS = f"{LAW}/misbehaving.py"


def json_text(obj: object) -> str:
    import json

    return json.dumps(obj)


PLUGIN = (
    text("site/corpus_broken_plugin-1.0.dist-info/METADATA", "Metadata-Version: 2.1\nName: corpus-broken-plugin\nVersion: 1.0\n"),
    text("site/corpus_broken_plugin-1.0.dist-info/entry_points.txt", "[twolink_pin.controllers]\ncorpus-broken = corpus_broken_plugin:Law\n"),
    text("site/corpus_broken_plugin.py", 'raise ImportError("corpus: this plug-in needs a package that is not installed")\n'),
)
"""An installed plug-in (a dist-info on PYTHONPATH) whose module fails to import."""
USERCODE = [
    C("usercode-simulate-law-exit-0", f"simulate {MIS}:ExitZero {SIM} --save run.npz", 1, err=("corpus-exit-zero", "sys.exit(0)", "t ="), absent=("run.npz",), note="sys.exit(0) in a law must not look like success"),
    C("usercode-simulate-law-exit-3", f"simulate {MIS}:ExitThree {SIM} --json", 1, err=("corpus-exit-three", "sys.exit(3)")),
    C("usercode-simulate-law-exit-0-proc", f"simulate {MIS}:ExitZero {SIM} --save run.npz", 1, err=("corpus-exit-zero", "sys.exit(0)"), run="proc", absent=("run.npz",)),
    C("usercode-simulate-law-exit-adaptive", f"simulate {MIS}:ExitZero {SIM} --method adaptive", 1, err=("corpus-exit-zero", "sys.exit(0)")),
    C("usercode-simulate-law-file-exits-on-import", f"simulate {LAW}/exit_on_import.py:Law {SIM}", 2, err=("exit_on_import.py", "sys.exit(0)")),
    C("usercode-sweep-law-exit-0", f"sweep {MIS}:ExitZero --samples 4 {SIM} --no-plot --out s", 1, err=("corpus-exit-zero", "sys.exit(0)"), absent=("s",), note="a sweep leaves no partial folder"),
    C("usercode-compare-law-exit-0", f"compare {MIS}:ExitZero pd {SIM} --no-plot --out c", 1, err=("corpus-exit-zero", "sys.exit(0)"), exists=("c/comparison.csv",), note="the law that exits is a failed row; pd's row is written"),
    C("usercode-simulate-law-writes-state", f"simulate {MIS}:WritesState {SIM} --save run.npz", 1, err=("corpus-writes-state", "read-only"), absent=("run.npz",)),
    C("usercode-simulate-law-writes-reference", f"simulate {MIS}:WritesReference {SIM}", 1, err=("corpus-writes-reference", "read-only", "reference")),
    C("usercode-simulate-law-writes-state-adaptive", f"simulate {MIS}:WritesState {SIM} --method adaptive", 1, err=("corpus-writes-state", "read-only")),
    C("usercode-simulate-law-memory", f"simulate {MIS}:Hog {SIM}", 1, err=("corpus-hog", "memory"), not_err=("please report",)),
    C("usercode-simulate-law-prints-json", f"simulate {MIS}:Printer {SIM} --json", 0, warns=("corpus-printer says hello",), checks=(strict_json(), json_at("stdout", "controller", "==", "corpus-printer")), note="a law's print goes to stderr with --json: stdout holds the JSON alone"),
    C("usercode-simulate-law-sleeps-timeout", f"simulate {MIS}:Sleeper {SIM} --timeout 2 --save run.npz", 1, err=("--timeout 2 s", "Sleeper"), run="proc", absent=("run.npz",), timeout=30),
    C("usercode-simulate-law-spins-timeout", f"simulate {MIS}:Spinner {SIM} --timeout 2 --method adaptive", 1, err=("--timeout 2 s", "Spinner"), run="proc", timeout=30),
    C("usercode-compare-law-sleeps-timeout", f"compare {MIS}:Sleeper pd {SIM} --timeout 2 --no-plot --out c", 1, err=("--timeout 2 s", "Sleeper"), run="proc", exists=("c/comparison.json",), timeout=30, note="--timeout bounds each run: the sleeper's run fails, pd's result is kept"),
    C("usercode-simulate-timeout-negative", f"simulate pd {SIM} --timeout -1", 2, err=("--timeout", "-1")),
    C("usercode-controllers-broken-plugin-warns", "controllers --json", 0, warns=("warning", "corpus-broken", "ImportError"), setup=PLUGIN, env=(("PYTHONPATH", "{dir}/site"),), run="proc", checks=(strict_json(),), note="the built-in laws are still listed; the broken plug-in is a warning, not silently missing"),
    C("usercode-simulate-broken-plugin-by-name", f"simulate corpus-broken {SIM}", 2, err=("corpus-broken", "plug-in", "ImportError", "not installed"), setup=PLUGIN, env=(("PYTHONPATH", "{dir}/site"),), run="proc"),
]

# == Bounded readers and outputs that would replace an input (issue 23) ================================
PFORMAT = "twolink-pin identified parameters"
DEEP_JSON = '{"times": ' + "[" * 5000 + "]" * 5000 + "}"
DEEP_TOML = "times = " + "[" * 5000 + "]" * 5000 + "\n"
PLAIN_TOML = "times = [0.0, 1.0, 2.0]\njoints = [[0.0, 0.0], [0.2, 0.1], [0.0, 0.0]]\n"
FOURIER = "[fourier]\nperiod = {}\nharmonics = 1\na = [[0.1], [0.1]]\nb = [[0.0], [0.0]]\noffset = [0.0, 0.0]\n"
READERS = [
    C("traceback-simulate-trajectory-json-deep", f"simulate pd {SIM} --trajectory deep.json", 2, err=("deep.json", "32 deep"), setup=(text("deep.json", DEEP_JSON),)),
    C("traceback-simulate-trajectory-toml-deep", f"simulate pd {SIM} --trajectory deep.toml", 2, err=("deep.toml", "32 deep"), setup=(text("deep.toml", DEEP_TOML),)),
    C("traceback-simulate-p0-json-deep", f"simulate adaptive {SIM} --p0 deep.json", 2, err=("deep.json", "32 deep"), setup=(text("deep.json", '{"format": ' + "[" * 100000 + "]" * 100000 + "}"),)),
    C("traceback-simulate-trajectory-json-deep-in-string", f"simulate pd {SIM} --trajectory t.json", 2, err=("t.json", "only the keys"), setup=(text("t.json", '{"times": [0, 1, 2], "joints": [[0, 0], [0.2, 0.1], [0, 0]], "comment": "' + "[" * 5000 + '"}'),), note="brackets inside a string are not nesting: the file is refused for its key, not its depth"),
    C("nonfinite-simulate-trajectory-times-overflow", f"simulate pd {SIM} --trajectory t.toml", 2, err=("times[1]", "1e+300", "1e+06"), setup=(text("t.toml", "times = [0, 1e300, 2e300]\njoints = [[0, 0], [0.2, 0.1], [0, 0]]\n"),)),
    C("nonfinite-simulate-trajectory-times-crowded", f"simulate pd {SIM} --trajectory t.toml", 2, err=("times[1]", "0.001 s"), setup=(text("t.toml", "times = [0, 1e-12, 2]\njoints = [[0, 0], [0.2, 0.1], [0, 0]]\n"),)),
    C("wrong-simulate-fourier-period-1e-300", f"simulate pd {SIM} --trajectory f.toml", 2, err=("fourier.period", "1e-300", "0.001"), setup=(text("f.toml", FOURIER.format("1e-300")),)),
    C("wrong-simulate-fourier-period-1e300", f"simulate pd {SIM} --trajectory f.toml", 2, err=("fourier.period", "1e+300|1e300", "1e+06"), setup=(text("f.toml", FOURIER.format("1e300")),)),
    C("wrong-simulate-p0-duplicate-parameter", f"simulate adaptive {SIM} --p0 p.json", 2, err=("p.json", "repeats", "'m1'"), setup=(text("p.json", json_text({"format": PFORMAT, "nv": 2, "robot": "twolink", "parameters": [{"name": "m1", "estimate": 1.0}, {"name": "m1", "estimate": 2.0}]})),)),
    C("wrong-simulate-p0-duplicate-key", f"simulate adaptive {SIM} --p0 p.json", 2, err=("p.json", "'nv'", "twice"), setup=(text("p.json", '{"format": "' + PFORMAT + '", "nv": 6, "nv": 2, "parameters": []}'),)),
    C("unclear-simulate-p0-other-robot", f"simulate adaptive {SIM} --p0 p.json", 2, err=("nv = 6", "expected nv = 2", "twolink"), not_err=("twolink has 2",), setup=(text("p.json", json_text({"format": PFORMAT, "nv": 6, "robot": "ur5", "parameters": []})),)),
    C("hang-identify-data-npz-bomb", "identify --data bomb.npz", 2, err=("bomb.npz", "claims"), setup=(blob("bomb.npz", npz_bomb),), run="proc", memory=2 * GiB, timeout=60, note="4 MB that inflate to 4 GiB: refused from the headers, before anything is inflated"),
    C("dataloss-simulate-save-over-trajectory", f"simulate pd {SIM} --trajectory t.toml --save t.toml", 2, err=("--save", "t.toml", "--trajectory"), setup=(text("t.toml", PLAIN_TOML),)),
    C("dataloss-simulate-save-over-trajectory-symlink", f"simulate pd {SIM} --trajectory t.toml --save link.npz", 2, err=("--save", "link.npz", "t.toml"), setup=(text("t.toml", PLAIN_TOML), symlink("link.npz", "t.toml"))),
    C("dataloss-identify-save-over-trajectory", "identify --trajectory t.toml --duration 2 --save t.toml", 2, err=("--save", "t.toml"), setup=(text("t.toml", PLAIN_TOML),)),
    C("dataloss-animate-html-over-from", "animate --from run.npz --html run.npz", 2, err=("--html", "run.npz"), setup=(SAVED,)),
    C("wrong-excite-infeasible", "excite --out e.toml --velocity-fraction 1e-12 --starts 1 --max-iterations 5 --samples 20", 1, err=("excite failed", "infeasible|not move", "e.toml"), absent=("e.toml",), note="an excitation beyond its limits is a failed run: exit 1, nothing written"),
    C("wrong-excite-period-1e-300", "excite --out e.toml --period 1e-300", 2, err=("--period", "1e-300", "0.001"), absent=("e.toml",)),
    C("hang-excite-months-of-work", "excite --out e.toml --starts 50 --max-iterations 100000 --samples 100000", 2, err=("1.1e+13", "2e+08"), absent=("e.toml",), note="each maximum is accepted alone; together they would run for months: refused before any work"),
    C("unclear-compare-out-symlink-to-empty-folder", f"compare pd {SIM} --no-plot --out link", 2, err=("link", "symbolic link", "empty"), setup=(folder("empty"), symlink("link", "empty")), checks=(still_symlink("link"),), note="refused (the swap would replace the link), saying so rather than 'not a directory'"),
    C("unclear-ik-just-outside-annulus", "ik 0.62000000001 0", 2, err=("r = 0.62000000001", "<= 0.62 m")),
    C("unclear-ik-just-inside-hole", "ik 0.13999999999 0", 2, err=("r = 0.13999999999", "0.14 <=")),
]

# == 6b. Library-level arguments =====================================================================
# The public functions raise InvalidParameterError naming the argument (expected vs received),
# not a numpy / Pinocchio / Python error, and never return NaN for NaN input.
Q0 = "np.zeros(2)"
LIBRARY = [
    LibCase("library-dynamics-mass_matrix-q-size-3", "dynamics.mass_matrix(model, data, np.zeros(3))", ("q", "(2,)")),
    LibCase("library-dynamics-mass_matrix-q-nan", "dynamics.mass_matrix(model, data, np.array([np.nan, 0.0]))", ("q", "finite")),
    LibCase("library-dynamics-mass_matrix-q-string", "dynamics.mass_matrix(model, data, 'ab')", ("q",)),
    LibCase("library-dynamics-mass_matrix-q-2d", "dynamics.mass_matrix(model, data, np.zeros((1, 2)))", ("q", "(2,)")),
    LibCase("library-dynamics-mass_matrix-model-none", f"dynamics.mass_matrix(None, data, {Q0})", ("model",)),
    LibCase("library-dynamics-mass_matrix-data-none", f"dynamics.mass_matrix(model, None, {Q0})", ("data",)),
    LibCase("library-dynamics-coriolis_matrix-v-size-3", f"dynamics.coriolis_matrix(model, data, {Q0}, np.zeros(3))", ("v", "(2,)")),
    LibCase("library-dynamics-coriolis_matrix-v-inf", f"dynamics.coriolis_matrix(model, data, {Q0}, np.array([np.inf, 0.0]))", ("v", "finite")),
    LibCase("library-dynamics-gravity_torque-q-size-1", "dynamics.gravity_torque(model, data, np.zeros(1))", ("q", "(2,)")),
    LibCase("library-dynamics-inverse_dynamics-a-size-3", f"dynamics.inverse_dynamics(model, data, {Q0}, {Q0}, np.zeros(3))", ("a", "(2,)")),
    LibCase("library-dynamics-inverse_dynamics-a-nan", f"dynamics.inverse_dynamics(model, data, {Q0}, {Q0}, np.array([0.0, np.nan]))", ("a", "finite")),
    LibCase("library-dynamics-inverse_dynamics-q-string", f"dynamics.inverse_dynamics(model, data, 'q', {Q0}, {Q0})", ("q",)),
    LibCase("library-dynamics-forward_dynamics-tau-size-3", f"dynamics.forward_dynamics(model, data, {Q0}, {Q0}, np.zeros(3))", ("tau", "(2,)")),
    LibCase("library-dynamics-forward_dynamics-tau-nan", f"dynamics.forward_dynamics(model, data, {Q0}, {Q0}, np.array([np.nan, 0.0]))", ("tau", "finite")),
    LibCase("library-dynamics-forward_dynamics-v-string", f"dynamics.forward_dynamics(model, data, {Q0}, 'v', {Q0})", ("v",)),
    LibCase("library-dynamics-model_torque-w-size-3", f"dynamics.model_torque(model, data, {Q0}, {Q0}, np.zeros(3), {Q0})", ("w", "(2,)")),
    LibCase("library-dynamics-model_torque-w-nan", f"dynamics.model_torque(model, data, {Q0}, {Q0}, np.array([np.nan, 0.0]), {Q0})", ("w", "finite")),
    LibCase("library-dynamics-regressor-a-size-3", f"dynamics.regressor(model, data, {Q0}, {Q0}, {Q0}, np.zeros(3))", ("a", "(2,)")),
    LibCase("library-dynamics-regressor-w-nan", f"dynamics.regressor(model, data, {Q0}, {Q0}, np.array([0.0, np.nan]), {Q0})", ("w", "finite")),
    LibCase("library-dynamics-joint_inertia-not-a-model", "dynamics.joint_inertia('twolink')", ("model",)),
    LibCase("library-dynamics-friction-negative-viscous", "dynamics.Friction((-1.0, 0.0), (0.0, 0.0))", ("viscous",)),
    LibCase("library-dynamics-friction-nan-coulomb", "dynamics.Friction((1.0, 1.0), (np.nan, 0.0))", ("coulomb",)),
    LibCase("library-dynamics-friction-lengths", "dynamics.Friction((1.0,), (1.0, 2.0))", ("coulomb",)),
    LibCase("library-dynamics-friction-negative-smoothing", "dynamics.Friction((1.0,), (1.0,), smoothing=-1.0)", ("smoothing",)),
    LibCase("library-dynamics-friction-string-values", "dynamics.Friction('ab', 'cd')", ("viscous",)),
    LibCase("library-dynamics-friction_regressor-negative-smoothing", f"dynamics.friction_regressor({Q0}, smoothing=-1.0)", ("smoothing",)),
    LibCase("library-dynamics-friction_regressor-v-nan", "dynamics.friction_regressor(np.array([np.nan, 0.0]))", ("v", "finite")),
    LibCase("library-kinematics-forward_kinematics-q-size-3", "kinematics.forward_kinematics(robot, np.zeros(3))", ("q", "(2,)")),
    LibCase("library-kinematics-forward_kinematics-q-nan", "kinematics.forward_kinematics(robot, np.array([np.nan, 0.0]))", ("q", "finite")),
    LibCase("library-kinematics-forward_kinematics-q-string", "kinematics.forward_kinematics(robot, 'ab')", ("q",)),
    LibCase("library-kinematics-forward_kinematics-pin-model", f"kinematics.forward_kinematics(model, {Q0})", ("robot", "RobotModel")),
    LibCase("library-kinematics-jacobian-q-size-1", "kinematics.jacobian(robot, np.zeros(1))", ("q", "(2,)")),
    LibCase("library-kinematics-joint_positions-three-columns", "kinematics.joint_positions(robot, np.zeros((4, 3)))", ("q", "2")),
    LibCase("library-kinematics-inverse_kinematics-target-three", "kinematics.inverse_kinematics(robot, (0.3, 0.2, 0.1))", ("target",)),
    LibCase("library-kinematics-inverse_kinematics-target-nan", "kinematics.inverse_kinematics(robot, (np.nan, 0.2))", ("target",)),
    LibCase("library-kinematics-inverse_kinematics-target-string", "kinematics.inverse_kinematics(robot, 'xy')", ("target",)),
    LibCase("library-kinematics-inverse_kinematics-unreachable", "kinematics.inverse_kinematics(robot, (1.0, 0.0))", ("1", "0.62"), exc="UnreachableTargetError"),
    LibCase("library-kinematics-inverse_kinematics-tol-negative", "kinematics.inverse_kinematics(robot, (0.3, 0.2), tol=-1.0)", ("tol",)),
    LibCase("library-kinematics-inverse_kinematics-tol-nan", "kinematics.inverse_kinematics(robot, (0.3, 0.2), tol=float('nan'))", ("tol",)),
    LibCase("library-kinematics-workspace-arm3", "kinematics.workspace(tp.load_robot(URDF / 'arm3.urdf'))", ("robot", "2")),
    LibCase("library-load_robot-payload-negative", "tp.load_robot(payload=-1.0)", ("payload",)),
    LibCase("library-load_robot-payload-nan", "tp.load_robot(payload=float('nan'))", ("payload",)),
    LibCase("library-load_robot-payload-inf", "tp.load_robot(payload=float('inf'))", ("payload",)),
    LibCase("library-load_robot-payload-string", "tp.load_robot(payload='2')", ("payload",)),
    LibCase("library-load_robot-payload-bool", "tp.load_robot(payload=True)", ("payload",)),
    LibCase("library-load_robot-unknown-name", "tp.load_robot('twolnk')", ("twolnk", "twolink"), exc="InvalidURDFError"),
    LibCase("library-load_robot-not-a-path", "tp.load_robot(42)", ("robot|42",), exc="InvalidParameterError|InvalidURDFError"),
    LibCase("library-load_robot-unknown-ee-frame", "tp.load_robot(ee_frame='hand')", ("hand",), exc="InvalidURDFError"),
    LibCase("library-load_robot-directory", "tp.load_robot(URDF)", ("directory",), exc="InvalidURDFError"),
    LibCase("library-load_robot-prismatic-ik", "kinematics.inverse_kinematics(tp.load_robot(URDF / 'prismatic.urdf'), (0.3, 0.2))", ("prismatic",)),
    LibCase("library-simulate-controller-string", "tp.simulate('pd', plant, trajectory)", ("controller",)),
    LibCase("library-simulate-plant-none", "tp.simulate(controller, None, trajectory)", ("plant",)),
    LibCase("library-simulate-trajectory-none", "tp.simulate(controller, plant, None)", ("trajectory",)),
    LibCase("library-simulate-config-dict", "tp.simulate(controller, plant, trajectory, {'duration': 1.0})", ("config",)),
    LibCase("library-simulate-q0-offset-three", "tp.simulate(controller, plant, trajectory, SimulationConfig(duration=0.01, q0_offset=(0.1, 0.2, 0.3)))", ("q0_offset", "2")),
    LibCase("library-simulationconfig-duration-nan", "SimulationConfig(duration=float('nan'))", ("duration",)),
    LibCase("library-simulationconfig-duration-string", "SimulationConfig(duration='1')", ("duration",)),
    LibCase("library-simulationconfig-dt-zero", "SimulationConfig(dt=0.0)", ("dt",)),
    LibCase("library-simulationconfig-dt-over-duration", "SimulationConfig(duration=0.5, dt=1.0)", ("dt",)),
    LibCase("library-simulationconfig-method-euler", "SimulationConfig(method='euler')", ("method", "rk4")),
    LibCase("library-simulationconfig-too-many-steps", "SimulationConfig(duration=1e6, dt=1e-6)", ("dt", str(MAX_STEPS))),
    LibCase("library-simulationconfig-control-period-not-multiple", "SimulationConfig(duration=1.0, control_period=0.0015)", ("control_period",)),
    LibCase("library-simulationconfig-q0-offset-nan", "SimulationConfig(q0_offset=(0.1, float('nan')))", ("q0_offset",)),
    LibCase("library-simulationconfig-rtol-negative", "SimulationConfig(rtol=-1.0)", ("rtol",)),
    LibCase("library-make_scenario-unknown-gain", "tp.make_scenario('pd', robot, gains={'zeta': 1.0})", ("zeta",)),
    LibCase("library-make_scenario-lam-on-pd", "tp.make_scenario('pd', robot, lam=3.0)", ("lambda", "pd")),
    LibCase("library-make_scenario-gain-nan", "tp.make_scenario('pd', robot, gains={'kp': float('nan')})", ("kp",)),
    LibCase("library-make_scenario-gain-three-values", "tp.make_scenario('pd', robot, gains={'kp': (1.0, 2.0, 3.0)})", ("kp",)),
    LibCase("library-plant-saturate-string", "tp.Plant(robot, saturate='yes')", ("saturate",)),
    LibCase("library-plant-pin-model", "tp.Plant(model)", ("robot",)),
    *OUTSIDE_LIBRARY,
]

# fmt: on


CASES: list[Case] = [
    *DATALOSS,
    *WRONG,
    *HANG,
    *TRACEBACK,
    *NONFINITE,
    *UNCLEAR,
    *INTERRUPT,
    *USERCODE,
    *READERS,
    *OUTSIDE,
]
"""Every command-line case."""


def counts() -> dict[str, int]:
    """Cases per class (what ``README.md`` lists)."""
    tally = Counter(case.cls for case in CASES)
    tally["library"] = len(LIBRARY)
    return dict(tally)


def _check_ids() -> None:
    ids = [c.id for c in CASES] + [c.id for c in LIBRARY]
    repeated = [i for i, n in Counter(ids).items() if n > 1]
    if repeated:
        raise ValueError(f"case ids used twice: {repeated}")


_check_ids()
