"""Corpus cases of issue 38's ``tune`` classes (the server side): a ``--host`` that cannot be
listened on, a host the network reaches, a port in use, ``--watch`` of a registered law,
SIGTERM and Ctrl-C on a serving tuner.

Kept apart from ``cases.py`` (same form, same ids' classes), as ``cases_variants.py`` is;
``tests/test_corpus.py`` runs them. The page's own bad input (a path out of the tuner's
folder, a law that never returns) is in ``tests/test_tune_server.py``: it needs the page.
"""

from __future__ import annotations

from corpus.cases import C
from corpus.spec import SIGINT, SIGTERM, Case

TUNE = "tune pd --no-browser --duration 0.5"
"""A tuner that serves a short run and opens no browser."""
NO_INTERFACE = "192.0.2.1"
"""An address of TEST-NET-1 (RFC 5737): documentation only, no machine's interface has it."""

# fmt: off
TUNE_CASES: list[Case] = [
    # --host that cannot be listened on: at once, naming the host and why (waited forever, no URL)
    C("hang-tune-host-unresolvable", f"{TUNE} --host nohost.invalid", 2, err=("--host", "nohost.invalid", "does not resolve"), timeout=30),
    C("hang-tune-host-no-interface", f"{TUNE} --host {NO_INTERFACE}", 2, err=("--host", NO_INTERFACE, "cannot listen"), timeout=30),
    C("hang-tune-host-empty", f"{TUNE} --host=", 2, err=("--host",), timeout=30, note="argparse's check of an empty text, or ours: either names --host"),
    # a port in use: one line, no "(viser) Server stopped" beside it (stdout, or stderr under --json)
    C("traceback-tune-port-in-use", f"{TUNE} --port {{port}}", 2, err=("{port}", "in use"), not_err=("viser",), run="proc", timeout=30),
    C("traceback-tune-port-in-use-json", f"{TUNE} --json --port {{port}}", 2, err=("{port}", "in use"), not_err=("viser",), run="proc", timeout=30),
    # a multicast or broadcast address: Linux binds and listens on it, no browser can connect (issue 48)
    C("wrong-tune-host-multicast", f"{TUNE} --host 224.0.0.1", 2, err=("--host", "224.0.0.1", "multicast address"), timeout=30),
    C("wrong-tune-host-broadcast", f"{TUNE} --host 255.255.255.255", 2, err=("--host", "255.255.255.255", "broadcast address"), timeout=30),
    # an option that would do nothing is refused
    C("wrong-tune-watch-registered-law", f"{TUNE} --watch", 2, err=("--watch", "'pd'", "path/to/law.py:Class")),
    # a host other than loopback serves, and says the page is reachable from the network
    C("unclear-tune-host-any-says-network", f"{TUNE} --host 0.0.0.0", 0, warns=("reachable from the network", "0.0.0.0"), run="signal", signal=(SIGINT, "serving", "group"), timeout=60),
    # SIGTERM: exit 143 "terminated", as every command (was 0); Ctrl-C stops it quietly (exit 0)
    C("interrupt-tune-sigterm", f"{TUNE} --json", 143, err=("terminated",), run="signal", signal=(SIGTERM, "serving", "parent"), timeout=60),
    C("interrupt-tune-sigint", TUNE, 0, out=("tuning pd at http://127.0.0.1:",), not_err=("viser",), run="signal", signal=(SIGINT, "serving", "group"), timeout=60),
]
# fmt: on

__all__ = ["TUNE_CASES"]
