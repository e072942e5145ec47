"""Corpus cases of issue 30's classes: ``--timeout`` exact at every size, stiff adaptive runs
that end fast, the library API's wrong types and NaN results, Dask at the process limit.

Kept apart from ``cases.py`` (same form, same ids' classes) so the lists there stay as they
are; ``tests/test_corpus.py`` runs both.
"""

from __future__ import annotations

from corpus.cases import REP, SIM, C
from corpus.spec import Case, LibCase

TIMEOUT = ("did not finish within --timeout", "pd")
"""What every --timeout message says: the bound and the law."""

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
    C("hang-compare-adaptive-lambda-1e5", "compare computed-torque --method adaptive --lambda 1e5 --no-plot --out c", 1, err=("computed-torque", "collapsed to about", "steps per dt"), changed=("c",), timeout=60),
]

LIMITS_LIBRARY: list[LibCase] = [
]
# fmt: on
