"""Corpus cases of issue 47's ``equations`` command: arms it refuses (a floating base, a planar
joint, a closed chain, more joints than it derives, no moving joint), a ``--timeout`` shorter
than the derivation, outputs it must not write (a FIFO, the URDF it reads), Ctrl-C while it
derives — and the arms it takes (a prismatic joint, a −z axis, a continuous joint) printed
without a warning.

Kept apart from ``cases.py`` (same form, same ids' classes); ``tests/test_corpus.py`` runs them.
"""

from __future__ import annotations

from corpus.cases import NOT_REGULAR, C
from corpus.spec import SIGINT, Case, fifo, text, twolink, urdf

LOOP = (
    '<joint name="joint2" type="revolute">',
    '<joint name="loop" type="revolute"><parent link="base_link"/><child link="link2"/>'
    '<axis xyz="0 0 1"/></joint>\n  <joint name="joint2" type="revolute">',
)
"""A second joint into link2: a closed chain."""

# fmt: off
EQUATIONS: list[Case] = [
    # arms it does not derive: one line naming the joint or link and why
    C("unclear-equations-floating-base", "equations --robot floating.urdf", 2, err=("joint 'joint1' is floating", "floating base"), setup=(urdf("floating"),)),
    C("unclear-equations-planar-joint", "equations --robot planar_joint.urdf", 2, err=("joint 'joint1' is planar", "revolute, continuous and prismatic"), setup=(urdf("planar_joint"),)),
    C("unclear-equations-spherical-joint", "equations --robot s.urdf", 2, err=("joint 'joint2' is spherical", "revolute, continuous or prismatic"), setup=(twolink("s.urdf", ('<joint name="joint2" type="revolute">', '<joint name="joint2" type="spherical">')),)),
    C("unclear-equations-closed-chain", "equations --robot loop.urdf", 2, err=("link 'link2' is the child of joints", "closed chain"), setup=(twolink("loop.urdf", LOOP),)),
    C("unclear-equations-too-many-joints", "equations --robot panda", 2, err=("7 moving joints", "at most 6", "--joints N")),
    C("unclear-equations-joints-beyond-the-arm", "equations --joints 3", 2, err=("joints = 3", "from 1 to 2")),
    C("unclear-equations-joints-zero", "equations --joints 0", 2, err=("--joints", "0")),
    C("unclear-equations-no-moving-joint", "equations --robot fixed_only.urdf", 2, err=("at least one moving joint",), setup=(urdf("fixed_only"),)),
    C("unclear-equations-entities", "equations --robot billion_laughs.urdf", 2, err=("billion_laughs.urdf",), setup=(urdf("billion_laughs"),), note="the joint pre-check skips a document with a DTD: the validator refuses it before any expansion"),
    C("nonfinite-equations-timeout-nan", "equations --timeout nan", 2, err=("--timeout", "nan")),
    C("unclear-equations-timeout-negative", "equations --timeout -1", 2, err=("--timeout", "-1")),
    C("hang-equations-timeout", "equations --robot ur5 --joints 4 --no-cache --timeout 0.05 --python m.py", 2, err=("did not finish within --timeout 0.05 s", "--joints N"), absent=("m.py",), run="proc", note="a process of its own: in-process, the runner's own alarm for hangs is the enclosing bound"),
    # outputs: never onto what it reads, never into a FIFO, nothing half-written
    C("dataloss-equations-python-onto-the-urdf", "equations --robot arm.urdf --python arm.urdf", 2, err=("--python", "arm.urdf"), setup=(twolink("arm.urdf"),), note="arm.urdf is byte-identical afterwards"),
    C("dataloss-equations-latex-fifo", "equations --latex pipe.tex", 2, err=("pipe.tex", NOT_REGULAR), setup=(fifo("pipe.tex"),), timeout=20),
    C("dataloss-equations-keeps-a-users-file-on-refusal", "equations --robot panda --python mine.py", 2, err=("7 moving joints",), setup=(text("mine.py", "# mine\n"),)),
    # arms it takes: a prismatic joint, an axis along −z, a continuous joint, with files written
    C("wrong-equations-prismatic", "equations --robot prismatic.urdf --python m.py --latex m.tex", 0, setup=(urdf("prismatic"),), exists=("m.py", "m.tex")),
    C("wrong-equations-axis-minus-z", "equations --robot axis_minus_z.urdf --json", 0, setup=(urdf("axis_minus_z"),)),
    C("wrong-equations-continuous", "equations --robot continuous.urdf", 0, setup=(urdf("continuous"),)),
    # Ctrl-C while the UR5's six joints are derived: 130, no file
    C("interrupt-equations-sigint", "equations --robot ur5 --no-cache --python m.py", 130, err=("interrupted",), run="signal", signal=(SIGINT, "running", "group"), absent=("m.py",)),
]
