"""A sweep's runs that ended early carry their reason in every file (``diverged_reason``):
runs.csv, runs.json and the Parquet dataset — for ``mpc``'s runs that could not plan within
their limits (the law's reason), and in the same column whatever the chunking."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from twolink_pin.cli import main

pytest.importorskip("pyarrow")


def test_runs_mpc_could_not_plan_say_why_in_csv_json_and_parquet(tmp_path: Path) -> None:
    """Started 3.5 ± 1 rad off (beyond joint 1's range for some draws), ``on_infeasible=fail``
    fixed for every run (a word, not a range): those runs end at t = 0 with the replan's reason; the others have none (empty in CSV, null in JSON and
    Parquet)."""
    import pyarrow.parquet as pq

    out = tmp_path / "s"
    argv = ["sweep", "mpc", "--samples", "4", "--chunk", "2", "--duration", "0.05"]
    argv += ["--q0-offset", "3.5", "0", "--q0-spread", "1", "--no-plot", "--out", str(out)]
    argv += ["--gain", "on_infeasible=fail"]  # the default relaxes the range and goes on
    assert main(argv) == 0
    with open(out / "runs.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    records = json.loads((out / "runs.json").read_text())
    table = pq.read_table(out / "runs")
    assert str(table.schema.field("diverged_reason").type) == "string"
    parquet = table.column("diverged_reason").to_pylist()
    assert any(r["diverged"] == "1" for r in rows) and any(r["diverged"] == "0" for r in rows)
    for row, record, text in zip(rows, records, parquet, strict=True):
        if row["diverged"] == "1":
            assert (
                "MPC replan at t = 0 s" in row["diverged_reason"]
                and "position range" in row["diverged_reason"]
            )
            assert record["diverged_reason"] == row["diverged_reason"] == text
        else:
            assert row["diverged_reason"] == "" and record["diverged_reason"] is None and text is None
