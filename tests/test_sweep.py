"""Tests of twolink_pin.studies.sweep (and .parquet): reproducibility bit for bit (whatever the
chunks and threads; each run's case from its own seed) of the CSV, JSON and Parquet tables,
the Parquet dataset equal to the CSV with the sweep's configuration and units in its metadata
and nulls for missing values, the automatic chunk rule, the summary against numpy on the written rows,
divergent cases counted rather than fatal, each row being the run it describes, a user's law
by file, a user's folder never overwritten, and the ``sweep`` command's parser and output.
"""

from __future__ import annotations

import argparse
import csv
import heapq
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq
import pytest

from twolink_pin.cli import build_parser
from twolink_pin.cli.commands import cmd_sweep
from twolink_pin.controllers import PDFeedforward, PDGains, WrongModel
from twolink_pin.errors import ControllerSpecError, InvalidParameterError, OutputError
from twolink_pin.metrics import compute_metrics
from twolink_pin.model import load_robot
from twolink_pin.plant import Plant
from twolink_pin.run_spec import RunSpec, make_scenario
from twolink_pin.simulation import SimulationConfig, simulate
from twolink_pin.studies.parquet import METADATA_KEY, read_columns, read_metadata
from twolink_pin.studies.sweep import (
    PERCENTILES,
    Cases,
    GainRange,
    SweepConfig,
    auto_chunk,
    run_sweep,
    sweep_metadata,
)
from twolink_pin.studies.sweep_cases import chunk_law
from twolink_pin.trajectory import build_trajectory

ROBOT = load_robot()
TRAJECTORY = build_trajectory(ROBOT)
SHORT = SimulationConfig(duration=0.05)


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _study(**changes) -> SweepConfig:  # type: ignore[no-untyped-def]
    run = RunSpec(
        law=changes.pop("controller", "pd"),
        simulation=changes.pop("simulation", SHORT),
        lam=changes.pop("lam", None),
    )
    base = {
        "samples": 12,
        "seed": 7,
        "q0_spread": 0.1,
        "param_error": 0.2,
        "gains": (GainRange("kp", 100.0, 400.0), GainRange("kd2", 20.0, 80.0)),
        "chunk": 5,
    }
    return SweepConfig(run, **(base | changes))


def _table(out: Path) -> pa.Table:
    return ds.dataset(out / "runs", format="parquet").to_table().sort_by("run")


def test_seeded_sweeps_are_reproducible_bit_for_bit_whatever_the_chunks_and_threads(tmp_path: Path) -> None:
    run_sweep(_study(), ROBOT, TRAJECTORY, tmp_path / "a", plot=False)
    run_sweep(_study(chunk=12, threads=1), ROBOT, TRAJECTORY, tmp_path / "b", plot=False)
    run_sweep(_study(chunk=None), ROBOT, TRAJECTORY, tmp_path / "auto", plot=False)
    for other in ("b", "auto"):
        for name in ("runs.csv", "runs.json", "summary.json"):
            assert (tmp_path / "a" / name).read_bytes() == (tmp_path / other / name).read_bytes(), name
        a, b = _table(tmp_path / "a"), _table(tmp_path / other)
        assert a.equals(b, check_metadata=True)
        for name in a.column_names:
            column_a, column_b = a.column(name).to_numpy(), b.column(name).to_numpy()
            assert column_a.tobytes() == column_b.tobytes(), name
    assert (
        len(list((tmp_path / "a" / "runs").iterdir())) == 3
        and len(list((tmp_path / "b" / "runs").iterdir())) == 1
    )
    run_sweep(_study(seed=8), ROBOT, TRAJECTORY, tmp_path / "c", plot=False)
    assert (tmp_path / "a" / "runs.csv").read_bytes() != (tmp_path / "c" / "runs.csv").read_bytes()


def test_a_runs_case_depends_only_on_the_seed_and_its_index(tmp_path: Path) -> None:
    """The first 5 rows of a 12-run sweep equal a 5-run sweep's rows, byte for byte."""
    run_sweep(_study(), ROBOT, TRAJECTORY, tmp_path / "a", plot=False)
    run_sweep(_study(samples=5), ROBOT, TRAJECTORY, tmp_path / "b", plot=False)
    a = (tmp_path / "a" / "runs.csv").read_text().splitlines()
    b = (tmp_path / "b" / "runs.csv").read_text().splitlines()
    assert a[:6] == b


def test_summary_statistics_are_numpy_percentiles_of_the_rows(tmp_path: Path) -> None:
    output = run_sweep(_study(), ROBOT, TRAJECTORY, tmp_path, plot=False)
    rows = _rows(tmp_path / "runs.csv")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary == output.summary
    assert summary["runs"] == len(rows) == 12
    assert summary["diverged"] == sum(r["diverged"] == "1" for r in rows) == 0
    assert summary["limit_exceeded"] == sum(r["limit_exceeded"] == "1" for r in rows)
    for name, stat in summary["metrics"].items():
        column = np.array([float(r[name]) for r in rows])
        p5, p50, p95 = np.percentile(column, PERCENTILES)
        assert (stat["p5"], stat["median"], stat["p95"]) == (p5, p50, p95), name
    json_rows = json.loads((tmp_path / "runs.json").read_text())
    assert [r["rms_e1"] for r in json_rows] == [float(r["rms_e1"]) for r in rows]


def test_rows_stream_to_a_parquet_dataset_with_the_sweep_in_its_metadata(tmp_path: Path) -> None:
    """One file per chunk under runs/; read as one dataset it is the CSV, value for value;
    every file carries the sweep's configuration (JSON) and every column its unit."""
    study = _study()
    output = run_sweep(study, ROBOT, TRAJECTORY, tmp_path, plot=False)
    parts = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert parts == ["part-0000000.parquet", "part-0000005.parquet", "part-0000010.parquet"]
    assert tmp_path / "runs" in output.files and output.chunk == 5 and output.engine == "in-process"
    table = ds.dataset(tmp_path / "runs", format="parquet").to_table()
    assert table.column("run").to_pylist() == list(range(12))  # the files sort in run order
    rows = _rows(tmp_path / "runs.csv")
    assert table.column_names == list(rows[0])
    for name in table.column_names:
        values = table.column(name).to_pylist()
        if name in ("limit_exceeded", "diverged"):
            assert values == [r[name] == "1" for r in rows], name
        elif name == "run":
            assert values == [int(r[name]) for r in rows]
        elif name == "diverged_reason":  # text: empty in the CSV where a run has none
            assert values == [r[name] or None for r in rows]
        else:
            assert values == [None if r[name] == "nan" else float(r[name]) for r in rows], name
    schema = table.schema
    assert schema.field("run").type == pa.int64() and schema.field("diverged").type == pa.bool_()
    units = {
        name: schema.field(name).metadata[b"unit"].decode()
        for name in ("q0_offset1", "rms_edot2", "gain_kp", "gain_kd2", "diverged_at", "peak_command1")
    }
    assert units == {
        "q0_offset1": "rad",
        "rms_edot2": "rad/s",
        "gain_kp": "N·m/rad",
        "gain_kd2": "N·m·s/rad",
        "diverged_at": "s",
        "peak_command1": "N·m",
    }
    expected = sweep_metadata(study, ROBOT, PDFeedforward, TRAJECTORY)
    for part in (tmp_path / "runs").iterdir():
        assert json.loads(pq.read_schema(part).metadata[METADATA_KEY]) == expected
    metadata = read_metadata(tmp_path / "runs")
    assert metadata == expected and metadata["seed"] == 7 and metadata["samples"] == 12
    assert metadata["gains"] == {"kp": [100.0, 400.0], "kd2": [20.0, 80.0]} and metadata["controller"] == "pd"
    assert metadata["q0_offset"] == [0.1, -0.1] and metadata["dt"] == SHORT.dt and "chunk" not in metadata
    assert (
        metadata["trajectory"]["via_q"] == np.asarray(TRAJECTORY.via_q).tolist()
    )  # the reference it tracked


def test_columns_are_read_back_in_run_order_every_kth_and_a_missing_chunk_is_refused(tmp_path: Path) -> None:
    run_sweep(_study(), ROBOT, TRAJECTORY, tmp_path, plot=False)
    rows = _rows(tmp_path / "runs.csv")
    columns = read_columns(tmp_path / "runs", ["run", "rms_e1", "diverged"], every=3)
    assert columns["run"].tolist() == [0, 3, 6, 9] and columns["diverged"].dtype == bool
    assert columns["rms_e1"].tolist() == [float(rows[i]["rms_e1"]) for i in (0, 3, 6, 9)]
    (tmp_path / "runs" / "part-0000005.parquet").unlink()
    with pytest.raises(InvalidParameterError, match="the 12 runs of its sweep, got 7"):
        read_columns(tmp_path / "runs", ["rms_e1"])
    with pytest.raises(
        InvalidParameterError,
        match=r"path = '.*nothing' is invalid: expected a sweep's runs/ folder \(part-\*\.parquet files\)",
    ):
        read_metadata(tmp_path / "nothing")


def test_the_automatic_chunk_is_min_n_1000_in_process_and_four_per_worker_on_a_cluster() -> None:
    assert [auto_chunk(n) for n in (1, 300, 1000, 1200, 5000)] == [1, 300, 1000, 600, 1000]
    assert [auto_chunk(n, 2) for n in (100, 200, 300, 4000, 10_000)] == [50, 100, 150, 500, 1000]
    assert auto_chunk(100_000, 64) == 391 and auto_chunk(1000, 64) == 8


@pytest.mark.parametrize("workers", [None, 1, 2, 3, 8, 64])
def test_every_worker_has_a_chunk_from_the_start_and_the_last_finishes_near_the_ideal(
    workers: int | None,
) -> None:
    """The issue's case: 200 runs on 2 workers made one chunk, so one worker did everything.
    Chunks handed out in order to whichever worker is free (as Dask does) must end within
    4/3 of the even split ``ceil(N / workers)`` runs per worker (the rest of a whole number
    of runs per chunk)."""
    slots = workers or 1
    for n in (*range(1, 40), 199, 200, 201, 999, 1000, 1001, 1200, 2500, 9999, 123_457):
        chunk = auto_chunk(n, workers)
        sizes = [min(chunk, n - s) for s in range(0, n, chunk)]
        assert 1 <= chunk <= 1000, (n, chunk)
        assert len(sizes) >= min(n, slots), (n, workers, sizes)  # no worker idle from the start
        busy = [0] * slots
        for size in sizes:
            heapq.heapreplace(busy, busy[0] + size)
        assert max(busy) <= 4 / 3 * math.ceil(n / slots) or workers is None, (n, workers, chunk)


def test_divergent_cases_are_counted_not_fatal(tmp_path: Path) -> None:
    """Kd up to 600 with dt = 5 ms: RK4 goes unstable above Kd ≈ 300, for those cases only."""
    study = _study(
        samples=10,
        gains=(GainRange("kd", 40.0, 600.0),),
        simulation=SimulationConfig(duration=0.5, dt=5e-3),
        param_error=0.0,
    )
    output = run_sweep(study, ROBOT, TRAJECTORY, tmp_path, plot=True)
    rows = _rows(tmp_path / "runs.csv")
    diverged = [r for r in rows if r["diverged"] == "1"]
    assert 0 < output.summary["diverged"] == len(diverged) < 10
    assert all(float(r["gain_kd"]) > 200 for r in diverged)
    assert all(r["rms_e1"] == "nan" and float(r["diverged_at"]) > 0 for r in diverged)
    table = _table(tmp_path)  # missing values are nulls in the dataset (SQL's aggregates skip them)
    assert table.column("rms_e1").null_count == len(diverged) == table.column("diverged").to_numpy().sum()
    assert table.column("diverged_at").null_count == 10 - len(diverged)
    kept = np.array([float(r["rms_e1"]) for r in rows if r["diverged"] == "0"])
    assert output.summary["metrics"]["rms_e1"]["median"] == np.median(kept)
    assert (tmp_path / "distributions.png").stat().st_size > 10_000


def test_a_row_is_the_run_it_describes(tmp_path: Path) -> None:
    """Rebuild case 3 by hand (offset, parameter error, gains) and simulate it alone."""
    study = _study()
    run_sweep(study, ROBOT, TRAJECTORY, tmp_path, plot=False)
    row = _rows(tmp_path / "runs.csv")[3]
    factors = np.array([float(row[f"param_factor_{n}"]) for n in ("p1", "p2", "p3")])
    kp, kd2 = float(row["gain_kp"]), float(row["gain_kd2"])
    controller = PDFeedforward(
        ROBOT, PDGains(kp=(kp, kp), kd=(40.0, kd2)), model_parameters=ROBOT.p * factors
    )
    q0 = (float(row["q0_offset1"]), float(row["q0_offset2"]))
    result = simulate(controller, Plant(ROBOT), TRAJECTORY, replace(SHORT, q0_offset=q0))
    metrics = compute_metrics(result)
    np.testing.assert_allclose([float(row["rms_e1"]), float(row["rms_e2"])], metrics.rms.e, rtol=1e-9)
    np.testing.assert_allclose(
        [float(row["peak_command2"])], np.abs(result.tau_command[:, 1]).max(), rtol=1e-9
    )


def test_cases_are_drawn_in_the_documented_ranges() -> None:
    cases = Cases(_study(samples=200), ROBOT, 0, 200)
    assert np.all(np.abs(cases.q0_offset - np.array([0.1, -0.1])) <= 0.1)
    assert np.all(np.abs(cases.param_factor - 1) <= 0.2)
    assert np.all((cases.gains["kp"] >= 100) & (cases.gains["kp"] <= 400))


def test_indexed_gains_change_one_entry_and_model_scale_reaches_robust() -> None:
    """kp=LO:HI sets both joints' Kp per run; kd2 only the second Kd; model_scale is robust's β."""
    study = _study(param_error=0.0)
    cases = Cases(study, ROBOT, 0, 12)
    law = chunk_law(study, ROBOT, cases, make_scenario("pd", ROBOT).controller)
    np.testing.assert_array_equal(
        np.broadcast_to(law.gains.kp, (12, 2)), np.repeat(cases.gains["kp"][:, None], 2, axis=1)
    )
    np.testing.assert_array_equal(law.gains.kd[:, 0], 40.0)
    np.testing.assert_array_equal(law.gains.kd[:, 1], cases.gains["kd2"])
    robust = replace(
        study, run=RunSpec(law="robust", simulation=SHORT), gains=(GainRange("model_scale", 0.2, 0.3),)
    )
    built = chunk_law(robust, ROBOT, Cases(robust, ROBOT, 0, 12), make_scenario("robust", ROBOT).controller)
    assert isinstance(built, WrongModel) and np.all(
        (built.gains.model_scale >= 0.2) & (built.gains.model_scale <= 0.3)
    )


def test_a_users_law_from_a_file_sweeps_like_a_built_in_one(tmp_path: Path) -> None:
    """The tutorial's sliding-mode law by path, with its own gains drawn (ks, phi): no divergence,
    every row tracked to a small error."""
    study = _study(
        controller="examples/sliding_mode.py:SlidingMode",
        gains=(GainRange("ks", 1.0, 5.0), GainRange("phi", 0.02, 0.1)),
    )
    output = run_sweep(
        replace(study, run=replace(study.run, simulation=SimulationConfig(duration=0.3))),
        ROBOT,
        TRAJECTORY,
        tmp_path,
        plot=False,
    )
    assert output.summary["controller"] == "sliding-mode" and output.summary["diverged"] == 0
    rows = _rows(tmp_path / "runs.csv")
    assert [float(r["gain_ks"]) for r in rows] and all(1.0 <= float(r["gain_ks"]) <= 5.0 for r in rows)


def test_a_users_folder_is_never_overwritten(tmp_path: Path) -> None:
    """--out into a non-empty folder the sweep did not write: OutputError, the folder untouched."""
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="refusing to overwrite"):
        run_sweep(_study(samples=2), ROBOT, TRAJECTORY, tmp_path, plot=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    run_sweep(_study(samples=2), ROBOT, TRAJECTORY, tmp_path / "s", plot=False)
    run_sweep(_study(samples=3), ROBOT, TRAJECTORY, tmp_path / "s", plot=False)  # its own: replaced
    assert len(_rows(tmp_path / "s" / "runs.csv")) == 3


@pytest.mark.parametrize(
    ("changes", "text"),
    [
        (
            {"gains": (GainRange("kq", 1.0, 2.0),)},
            "gain = 'kq' is invalid: expected one of the gains of 'pd': kp, kd",
        ),
        ({"param_error": 1.0}, r"a fraction in \[0, 1\)"),
        ({"simulation": SimulationConfig(method="adaptive")}, "'rk4'"),
        ({"seed": -1}, "seed = -1 is invalid: expected a whole number >= 0"),
        ({"samples": 10**9}, "samples = 1000000000 is invalid: expected a whole number from 1 to 10000000"),
        ({"lam": 3.0}, "lambda = 3.0 is invalid"),
    ],
)
def test_bad_studies_are_refused_naming_the_value(changes: dict, text: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(InvalidParameterError, match=text):
        _study(**changes)


def test_an_unknown_law_is_refused_listing_the_registered_ones() -> None:
    with pytest.raises(ControllerSpecError, match="registered laws are pd, computed-torque, robust"):
        _study(controller="lqr")


def test_gain_range_text_is_parsed_or_refused_with_an_example() -> None:
    assert GainRange.parse("kp=100:400") == GainRange("kp", 100.0, 400.0)
    for bad in ("kp", "kp=1", "kp=4:1", "=1:2", "kp=a:b"):
        with pytest.raises(InvalidParameterError, match="NAME=LO:HI"):
            GainRange.parse(bad)


def test_trajectories_are_kept_only_when_asked(tmp_path: Path) -> None:
    output = run_sweep(_study(samples=6), ROBOT, TRAJECTORY, tmp_path, keep_trajectories=True, plot=False)
    kept = sorted(tmp_path.glob("trajectories-*.npz"))
    assert [p.name for p in kept] == ["trajectories-0000000.npz", "trajectories-0000005.npz"]
    assert set(kept) <= set(output.files)
    with np.load(kept[0]) as data:
        assert data["q"].shape == (5, SHORT.steps + 1, 2)


# --- the command --------------------------------------------------------------------------------------


def _parser() -> argparse.ArgumentParser:
    """The real CLI parser: the sweep command is wired as users run it."""
    return build_parser()


def test_sweep_command_prints_json_and_a_progress_bar(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # the bar shows on a terminal only
    argv = ["sweep", "computed-torque", "--samples", "4", "--duration", "0.05", "--q0-spread", "0.2"]
    argv += ["--gain", "lam=2:8", "--out", str(tmp_path), "--json", "--no-plot"]
    args = _parser().parse_args(argv)
    assert args.func is cmd_sweep
    assert cmd_sweep(args) == 0
    captured = capsys.readouterr()
    payload = json.loads(captured.out)
    assert payload["runs"] == 4 and payload["diverged"] == 0 and payload["gains"] == {"lam": [2.0, 8.0]}
    assert payload["engine"] == "in-process" and payload["chunk"] == 4 and args.chunk is None  # auto
    assert "100%" in captured.err and "4/4" in captured.err  # the progress display, on stderr
    assert len(_rows(tmp_path / "runs.csv")) == 4


def test_sweep_command_text_summary(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["sweep", "adaptive", "--samples", "3", "--duration", "0.05", "--param-error", "0.3"]
    args = _parser().parse_args([*argv, "--out", str(tmp_path), "--no-plot"])
    assert cmd_sweep(args) == 0
    out = capsys.readouterr().out
    assert out.startswith("sweep adaptive on twolink: 3 runs in ")
    assert "\n  ran in-process, in chunks of 3 runs\n" in out
    assert "p_hat_final_p3" in out and f"wrote {tmp_path / 'summary.json'}" in out


@pytest.mark.parametrize(
    "bad",
    [["--gain", "kp"], ["--param-error", "1.5"], ["--samples", "0"], ["--chunk", "some"], ["--chunk", "0"]],
)
def test_sweep_command_refuses_bad_options(bad: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        _parser().parse_args(["sweep", "pd", "--samples", "3", *bad])
    assert info.value.code == 2
    assert "error" in capsys.readouterr().err


def test_a_sweep_whose_runs_all_diverge_writes_its_table_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Kd from 2000 to 3000 with dt = 5 ms: RK4 is unstable for every case (above Kd ≈ 300).
    The table and summary are written (every row flagged), the summary says why there is no
    figure, and the command says so too."""
    from twolink_pin.cli import main

    argv = ["sweep", "pd", "--samples", "4", "--duration", "0.5", "--dt", "5e-3", "--gain", "kd=2000:3000"]
    assert main([*argv, "--out", str(tmp_path / "s")]) == 0
    out = capsys.readouterr()
    assert "every one of the 4 runs diverged" in out.out + out.err
    rows = _rows(tmp_path / "s" / "runs.csv")
    assert len(rows) == 4 and all(r["diverged"] == "1" for r in rows)
    summary = json.loads((tmp_path / "s" / "summary.json").read_text())
    assert summary["diverged"] == 4 and "every one" in summary["note"]
    assert not (tmp_path / "s" / "distributions.png").exists()


def test_an_output_folder_that_is_a_mount_point_is_refused_before_any_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A mount point cannot be swapped for the finished folder: refused at the start (one line,
    exit 2), not after the runs. (The mount is simulated: os.path.ismount says so for it.)"""
    import os

    from twolink_pin.cli import main

    mounted = tmp_path / "mnt"
    mounted.mkdir()
    real = os.path.ismount
    monkeypatch.setattr(os.path, "ismount", lambda p: Path(p) == mounted or real(p))
    progress: list[int] = []
    with pytest.raises(OutputError, match="mount point"):
        run_sweep(_study(), ROBOT, TRAJECTORY, mounted, progress=lambda done, total: progress.append(done))
    assert progress == [] and list(mounted.iterdir()) == []
    assert main(["sweep", "pd", "--samples", "2", "--duration", "0.05", "--out", str(mounted)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "mount point" in err


def test_a_drawn_matrix_gain_is_a_per_run_stack_and_run_i_is_that_single_run(tmp_path: Path) -> None:
    """On osc (matrix gains Kp, Kd, 3×3 SPD): kd=LO:HI is s·I per run, kp1=LO:HI the nominal
    Kp with entry (1, 1) drawn; the chunk's law holds (N, 3, 3) stacks, and row 2 of the
    table is a single simulate with those matrices."""
    study = _study(
        controller="osc",
        samples=4,
        q0_spread=0.0,
        param_error=0.0,
        gains=(GainRange("kp1", 50.0, 150.0), GainRange("kd", 5.0, 15.0)),
    )
    nominal = make_scenario("osc", ROBOT).controller
    cases = Cases(study, ROBOT, 0, 4)
    law = chunk_law(study, ROBOT, cases, nominal)
    assert np.shape(law.gains.kp) == (4, 3, 3) and np.shape(law.gains.kd) == (4, 3, 3)
    np.testing.assert_array_equal(law.gains.kd, cases.gains["kd"][:, None, None] * np.eye(3))
    np.testing.assert_array_equal(law.gains.kp[:, 0, 0], cases.gains["kp1"])
    np.testing.assert_array_equal(
        law.gains.kp[:, 1:, 1:], np.broadcast_to(nominal.gains.kp[:, 1:, 1:], (4, 2, 2))
    )
    run_sweep(study, ROBOT, TRAJECTORY, tmp_path, plot=False)
    row = _rows(tmp_path / "runs.csv")[2]
    kp = np.array(nominal.gains.kp[0])
    kp[0, 0] = float(row["gain_kp1"])
    kd = float(row["gain_kd"]) * np.eye(3)
    single = simulate(*make_scenario("osc", ROBOT, gains={"kp": kp, "kd": kd}), TRAJECTORY, SHORT)
    metrics = compute_metrics(single)
    np.testing.assert_allclose([float(row["rms_e1"]), float(row["rms_e2"])], metrics.rms.e, rtol=1e-9)
    np.testing.assert_allclose([float(row["max_tau1"]), float(row["max_tau2"])], metrics.max.tau, rtol=1e-9)


def test_a_drawn_matrix_that_is_not_positive_definite_is_refused_naming_the_run(tmp_path: Path) -> None:
    study = _study(controller="osc", samples=3, gains=(GainRange("kp1", -10.0, -1.0),))
    with pytest.raises(InvalidParameterError, match=r"kp\[0\].*positive definite"):
        run_sweep(study, ROBOT, TRAJECTORY, tmp_path / "o", plot=False)
    with pytest.raises(InvalidParameterError, match="diagonal entry from 1 to 3"):
        bad = _study(controller="osc", samples=3, gains=(GainRange("kp4", 1.0, 2.0),))
        chunk_law(bad, ROBOT, Cases(bad, ROBOT, 0, 3), make_scenario("osc", ROBOT).controller)
    assert not (tmp_path / "o").exists()
