"""Corpus cases of issue 38's classes outside ``tune``: gains given twice, a count of numbers
refused as an entry, a gain error that does not name its law, sweep draws that ``simulate``
would refuse, and the variant grammar ``LAW@KEY=VALUE`` of ``compare`` and ``report``.

Kept apart from ``cases.py`` (same form, same ids' classes), as ``cases_limits.py`` is;
``tests/test_corpus.py`` runs them.
"""

from __future__ import annotations

from pathlib import Path

from corpus.cases import REP, SIM, C
from corpus.spec import Case, LibCase, symlink

REPO = (symlink("repo", str(Path(__file__).resolve().parents[2])),)
"""The repository as ``repo`` in the case folder (its ``examples/`` laws), run from there."""
MATRIX = "30,0,0,0,30,0,0,0,30"
"""A 3 × 3 matrix gain, row by row."""

# fmt: off
GAINS: list[Case] = [
    # the same gain twice: refused naming it (was the last one, silently)
    C("wrong-simulate-gain-matrix-then-number", f"simulate osc --robot ur5 {SIM} --gain kd={MATRIX} --gain kd=50", 2, err=("--gain kd", "given twice", "kd=50")),
    C("wrong-simulate-gain-twice", f"simulate pd {SIM} --gain kp=100 --gain kp=200", 2, err=("kp", "given twice")),
    C("wrong-compare-gain-twice", f"compare pd computed-torque {SIM} --no-plot --out c --gain pd.kp=1 --gain pd.kp=2", 2, err=("pd.kp", "given twice"), absent=("c",)),
    C("wrong-report-gain-twice", f"report {REP} --out r --gain pd.kd=1 --gain pd.kd=2", 2, err=("pd.kd", "given twice"), absent=("r",)),
    # a count of numbers the gain cannot take: the count received and the counts expected, not an entry
    C("unclear-simulate-gain-four-numbers-two-joints", f"simulate pd {SIM} --gain kp=1,0,0,4", 2, err=("kp", "1 or 2 numbers (per joint, nv = 2); got 4"), not_err=("kp[1]",)),
    C("unclear-simulate-adaptive-gamma-two-of-three", f"simulate adaptive {SIM} --gain gamma=1,0", 2, err=("gamma", "1 or 3 numbers", "got 2"), not_err=("gamma[1]",)),
    C("unclear-simulate-osc-matrix-gain-two-numbers", f"simulate osc --robot ur5 {SIM} --gain kp=1,0", 2, err=("kp", "2 numbers are neither 1, 3 (a diagonal) nor 9 (a 3 × 3 matrix, row by row)"), not_err=("diagonal entry",)),
    # compare's gain error names the law (its row)
    C("unclear-compare-gain-count-names-the-law", f"compare pd computed-torque {SIM} --no-plot --out c --gain computed-torque.k=1,2,3", 2, err=("computed-torque: k", "got 3"), absent=("c",)),
    C("unclear-compare-gain-value-names-the-law", f"compare pd computed-torque {SIM} --no-plot --out c --gain pd.kp=-1", 2, err=("pd: kp = -1.0",), absent=("c",)),
    C("unclear-report-gain-value-names-the-law", f"report {REP} --out r --gain pd.kd=0", 2, err=("pd: kd = 0.0",), absent=("r",)),
    # sweep draws checked as simulate checks a value, before anything is written
    C("wrong-sweep-matrix-gain-draws-below-range", f"sweep osc --robot ur5 --samples 2 {SIM} --gain kp=0:1e-300 --no-plot --out s", 2, err=("--gain kp=0:1e-300", "run 0", "below 1e-12"), absent=("s",)),
    C("wrong-sweep-matrix-gain-entry-draws-below-range", f"sweep osc --robot ur5 --samples 2 {SIM} --gain kp2=1e-300:1e-299 --no-plot --out s", 2, err=("kp2", "below 1e-12"), absent=("s",)),
    C("wrong-sweep-user-law-matrix-gain-draws", f"sweep examples/jacobian_transpose.py:JacobianTranspose --robot ur5 --samples 2 {SIM} --gain k=0:1e-300 --no-plot --out s", 2, err=("--gain k=0:1e-300", "jacobian-transpose", "below 1e-12"), cwd="repo", setup=REPO, absent=("repo/s",)),
    C("wrong-sweep-user-law-gain-draws", f"sweep examples/sliding_mode.py:SlidingMode --samples 2 {SIM} --gain k=0:1e-300 --no-plot --out s", 2, err=("--gain k=0:1e-300", "run 0", "sliding-mode"), cwd="repo", setup=REPO, absent=("repo/s",)),
    C("wrong-simulate-matrix-gain-below-range", f"simulate osc --robot ur5 {SIM} --gain kp=1e-301,0,0,0,1e-301,0,0,0,1e-301", 2, err=("kp", "smallest eigenvalue", "below 1e-12"), note="9 numbers passed the Cholesky check; a number s was refused below 1e-12 already"),
    # variants: LAW@KEY=VALUE in compare and report
    C("unclear-compare-variant-unknown-key", f"compare pd pd@zeta=1 {SIM} --no-plot --out c", 2, err=("pd@zeta=1", "zeta", "a gain of 'pd' (kp, kd), model, p0 or a plant key"), absent=("c",)),
    C("wrong-compare-variant-key-twice", f"compare pd pd@kp=1@kp=2 {SIM} --no-plot --out c", 2, err=("kp is given twice",), absent=("c",)),
    C("traceback-compare-variant-empty-value", f"compare pd pd@kp= {SIM} --no-plot --out c", 2, err=("a value after 'kp='",), absent=("c",)),
    C("traceback-compare-variant-at-nothing", f"compare pd pd@ {SIM} --no-plot --out c", 2, err=("pd@", "nothing follows it"), absent=("c",)),
    C("wrong-compare-same-variant-twice", f"compare pd@kd=50@kp=100 pd@kp=100@kd=50 {SIM} --no-plot --out c", 2, err=("each variant once", "same run"), absent=("c",)),
    C("wrong-compare-same-law-twice", f"compare pd pd {SIM} --no-plot --out c", 2, err=("each variant once",), absent=("c",)),
    C("unclear-compare-variant-p0-on-pd", f"compare pd pd@p0=x.json {SIM} --no-plot --out c", 2, err=("'pd' estimates none",), absent=("c",)),
    C("unclear-compare-variant-gain-count", f"compare pd pd@kp=1,2,3 {SIM} --no-plot --out c", 2, err=("pd@kp=1,2,3: kp", "got 3"), absent=("c",)),
    C("unclear-compare-variant-model-missing", f"compare computed-torque computed-torque@model=nothere.urdf {SIM} --no-plot --out c", 2, err=("nothere.urdf: file", "file not found"), absent=("c",)),
    C("unclear-compare-two-variants", f"compare pd pd@kp=200,150 {SIM} --no-plot --out c --json", 0, out=('"pd@kp=200,150"',), exists=("c/comparison.csv",)),
    C("unclear-report-variant", f"report {REP} --controller pd@kd=20 --out r", 0, exists=("r/figures/pd_variants.png",)),
    C("unclear-report-variant-unknown-key", f"report {REP} --controller pd@lam=3 --out r", 2, err=("lam", "a gain of 'pd' (kp, kd)"), absent=("r",)),
]

GAINS_LIBRARY: list[LibCase] = [
    LibCase("library-make_scenario-gain-four-numbers-two-joints", "tp.make_scenario('pd', robot, gains={'kp': (1.0, 0.0, 0.0, 4.0)})", ("kp", "1 or 2 numbers", "got 4")),
    LibCase("library-parse_variant-unknown-key", "__import__('twolink_pin.law_variant').law_variant.parse_variant('pd@zeta=1')", ("zeta", "kp, kd")),
    LibCase("library-format_variant-model-and-p0", "__import__('twolink_pin.law_variant').law_variant.format_variant('adaptive', model='a.json', p0='b.json')", ("one parameter file per run",)),
]
# fmt: on
