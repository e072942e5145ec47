"""The ``sweep`` command's own options: the runs and what each draws (``--samples``,
``--seed``, ``--q0-spread``, ``--param-error``, ``--gain NAME=LO:HI``, ``--wrench-scale``) and
where the chunks run (``--threads``, ``--chunk``, ``--workers``, ``--scheduler``,
``--connect-timeout``); the command itself is assembled in :mod:`twolink_pin.cli.parser`.
"""

from __future__ import annotations

import argparse
from typing import Any

from twolink_pin.cli.arguments import MAX_OFFSET, MAX_TEXT, bounded, gain_range, whole
from twolink_pin.cli.disturbance_options import scale_range


def chunk_size(high: int) -> Any:
    """``sweep --chunk``: ``auto`` (None) or a whole number from 1 to ``high``."""
    number = whole(1, high)

    def parse(text: str) -> int | None:
        return None if text.strip().lower() == "auto" else number(text)

    return parse


def scheduler_option(text: str) -> str:
    """``sweep --scheduler``: a Dask scheduler's address, normalised (``tcp://HOST:PORT``)."""
    from twolink_pin.errors import InvalidParameterError
    from twolink_pin.studies.cluster import scheduler_address

    try:
        return scheduler_address(text)
    except InvalidParameterError as exc:
        raise argparse.ArgumentTypeError(f"expected {exc.expected}, got {text[:MAX_TEXT]!r}") from None


def add_sweep_draws(p: argparse.ArgumentParser) -> None:
    """The study's runs and what each draws: count, seed, initial error, parameter error,
    gain ranges, wrench scale."""
    from twolink_pin.studies.sweep import MAX_SAMPLES

    p.add_argument(
        "--samples",
        type=whole(1, MAX_SAMPLES),
        required=True,
        metavar="N",
        help=f"number of runs (1 to {MAX_SAMPLES})",
    )
    p.add_argument(
        "--seed",
        type=whole(0, 2**63 - 1),
        default=0,
        help="random seed >= 0 (default 0): same seed, same files",
    )
    p.add_argument(
        "--q0-spread",
        type=bounded(0.0, MAX_OFFSET, unit="rad"),
        default=0.0,
        metavar="RAD",
        help="initial error q0-offset ± U(RAD) per joint [rad] (default 0)",
    )
    p.add_argument(
        "--param-error",
        type=bounded(0.0, 0.999999, unit=""),
        default=0.0,
        metavar="FRAC",
        help="the law believes p·(1 + U(±FRAC)) per parameter (0 to <1, default 0)",
    )
    p.add_argument(
        "--gain",
        type=gain_range,
        action="append",
        default=[],
        metavar="NAME=LO:HI",
        help="draw a gain uniformly, e.g. kp=100:400, kd2=20:80, lam=1:10, model_scale=0.2:1; or fix a gain "
        "that is a word for every run, e.g. on_infeasible=fail (repeatable)",
    )
    p.add_argument(
        "--wrench-scale",
        type=scale_range,
        default=None,
        metavar="LO:HI",
        help="draw each run's factor on --wrench uniformly in [LO, HI], e.g. 0:2",
    )


def add_sweep_engine(p: argparse.ArgumentParser) -> None:
    """Where and how the chunks run: threads, chunk size, a LocalCluster or a scheduler."""
    from twolink_pin.studies.cluster import CONNECT_TIMEOUT, MAX_WORKERS
    from twolink_pin.studies.sweep import MAX_CHUNK

    p.add_argument(
        "--threads",
        type=whole(1, 256),
        default=None,
        help="threads of the batch engine per chunk (default the cores this process may use, or "
        "TWOLINK_PIN_THREADS, in-process; 1 per Dask task)",
    )
    p.add_argument(
        "--chunk",
        type=chunk_size(MAX_CHUNK),
        default=None,
        metavar="N|auto",
        help=f"runs per batch, one Dask task each (1 to {MAX_CHUNK}; default auto: equal chunks of at most 1000 "
        "in-process; on a cluster about 4 per worker within 250..1000, never fewer chunks than workers)",
    )
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--workers",
        type=whole(1, MAX_WORKERS),
        default=None,
        metavar="N",
        help=f"run on a Dask LocalCluster of N worker processes on this machine, bound to 127.0.0.1 "
        f"(1 to {MAX_WORKERS}; needs twolink-pin[cluster])",
    )
    where.add_argument(
        "--scheduler",
        type=scheduler_option,
        default=None,
        metavar="ADDRESS",
        help="run on the Dask scheduler at tcp://HOST:PORT or tls://HOST:PORT (see docs/cluster.md; "
        "needs twolink-pin[cluster])",
    )
    p.add_argument(
        "--connect-timeout",
        type=bounded(0.0, 3600.0, low_open=True, unit="s"),
        default=CONNECT_TIMEOUT,
        metavar="S",
        help=f"seconds for the scheduler to answer and have a worker (default {CONNECT_TIMEOUT:g})",
    )
