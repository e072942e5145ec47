"""Tests of twolink_pin.studies.cluster and sweeps on Dask: a real ``dask scheduler`` and
``dask worker`` processes on 127.0.0.1 (subprocesses of the test, always torn down), no
mock. The same sweep in-process, on a LocalCluster of 2 workers and on that scheduler (in
other chunks) gives identical Parquet tables, column by column, bit for bit, and identical
CSV/JSON/summary bytes; killing a worker (SIGKILL) in the middle of its task still gives
the identical table; Ctrl-C / SIGTERM cancel the tasks and leave no output and no process;
an unreachable or silent scheduler fails fast naming its address; bad options are one
line; the LocalCluster listens on 127.0.0.1 only; a worker with other versions is refused.
"""

from __future__ import annotations

import contextlib
import glob
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import psutil
import pyarrow as pa
import pyarrow.dataset as ds
import pytest
from distributed import Client

from twolink_pin.cli import build_parser, main
from twolink_pin.cli.commands import cmd_sweep
from twolink_pin.errors import ControllerError
from twolink_pin.model import load_robot
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig
from twolink_pin.studies import cluster as cluster_module
from twolink_pin.studies import sweep as sweep_module
from twolink_pin.studies.cluster import ClusterError, open_cluster, scheduler_address
from twolink_pin.studies.sweep import GainRange, SweepConfig, run_sweep
from twolink_pin.trajectory import default_trajectory

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
DASK = str(BIN / "dask")
TWOLINK_PIN = str(BIN / "twolink-pin")
ROBOT = load_robot()
TRAJECTORY = default_trajectory(ROBOT)
STUDY = SweepConfig(
    RunSpec(law="pd", simulation=SimulationConfig(duration=0.5, dt=2e-3)),  # 42 of 300 runs diverge: nulls
    samples=300,
    seed=11,
    q0_spread=0.2,
    param_error=0.3,
    gains=(GainRange("kp", 100.0, 400.0), GainRange("kd", 40.0, 600.0)),
)
STARTUP = 120.0
"""Generous bound on starting a scheduler or workers [s]: a guard against a hang, not an assertion."""


def _deadline_wait(ready: Any, what: str, seconds: float = STARTUP) -> None:
    end = time.monotonic() + seconds
    while not ready():
        if time.monotonic() > end:
            raise RuntimeError(f"{what} did not happen within {seconds:g} s")
        time.sleep(0.05)


class DaskProcesses:
    """A real ``dask scheduler`` and ``dask worker`` processes on 127.0.0.1."""

    def __init__(self, folder: Path, workers: int, nanny: bool) -> None:
        self.folder = folder
        self.file = folder / "scheduler.json"
        self.log = open(folder / "dask.log", "w")  # closed in stop()
        self.scheduler: subprocess.Popen[bytes] | None = None
        self.workers: list[subprocess.Popen[bytes]] = []
        self.nanny = nanny
        self.count = workers

    def start(self) -> DaskProcesses:
        cwd = self.folder / "workers-cwd"  # not the tests' cwd: relative paths do not resolve there
        cwd.mkdir(exist_ok=True)
        local = ["--host", "127.0.0.1", "--dashboard-address", "127.0.0.1:0"]  # docs/cluster.md
        scheduler = [DASK, "scheduler", *local, "--port", "0", "--scheduler-file", str(self.file)]
        self.scheduler = subprocess.Popen(scheduler, stdout=self.log, stderr=self.log, cwd=cwd)
        _deadline_wait(lambda: self.file.exists() and self.file.stat().st_size > 0, "the scheduler file")
        worker = [
            DASK,
            "worker",
            "--scheduler-file",
            str(self.file),
            "--nworkers",
            "1",
            "--nthreads",
            "1",
            *local,
        ]
        worker += ["--preload", "twolink_pin.studies.sweep", *([] if self.nanny else ["--no-nanny"])]
        for _ in range(self.count):
            self.workers.append(subprocess.Popen(worker, stdout=self.log, stderr=self.log, cwd=cwd))
        with self.client() as client:
            client.wait_for_workers(self.count, timeout=STARTUP)
        return self

    @property
    def address(self) -> str:
        return str(json.loads(self.file.read_text())["address"])

    @contextlib.contextmanager
    def client(self) -> Iterator[Client]:
        client = Client(self.address, timeout=STARTUP, set_as_default=False)
        try:
            yield client
        finally:
            client.close()

    def stop(self) -> None:
        """Workers first, then the scheduler (a worker that loses its scheduler while closing
        lingers for its nanny's 8-s kill timeout); SIGINT, Dask's graceful stop; SIGKILL after 20 s."""
        for group in (self.workers, [self.scheduler] if self.scheduler else []):
            for process in group:
                if process.poll() is None:
                    process.send_signal(signal.SIGINT)
            for process in group:
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
        self.log.close()


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory: pytest.TempPathFactory) -> Iterator[DaskProcesses]:
    """A scheduler and two workers (with nannies, as deployed), shared by this module's tests."""
    processes = DaskProcesses(tmp_path_factory.mktemp("dask"), workers=2, nanny=True)
    try:
        yield processes.start()
    finally:
        processes.stop()


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """STUDY run in-process, automatic chunks."""
    out = tmp_path_factory.mktemp("reference") / "sweep"
    run_sweep(STUDY, ROBOT, TRAJECTORY, out, plot=False)
    return out


def _table(out: Path) -> pa.Table:
    return ds.dataset(out / "runs", format="parquet").to_table().sort_by("run")


def assert_identical(a: Path, b: Path) -> None:
    """The Parquet tables of two sweeps equal column by column, bit for bit (nulls at the
    same rows), and their CSV, JSON and summary equal byte for byte."""
    ta, tb = _table(a), _table(b)
    assert ta.schema.equals(tb.schema, check_metadata=True)
    assert ta.num_rows == tb.num_rows
    for name in ta.column_names:
        ca, cb = ta.column(name), tb.column(name)
        assert ca.null_count == cb.null_count, name
        np.testing.assert_array_equal(
            ca.is_null().to_numpy(zero_copy_only=False), cb.is_null().to_numpy(zero_copy_only=False)
        )
        va = ca.to_numpy(zero_copy_only=False)
        vb = cb.to_numpy(zero_copy_only=False)
        if va.dtype == object:  # text (a run's diverged_reason): its values, not their pointers
            assert va.tolist() == vb.tolist(), name
            continue
        assert va.dtype == vb.dtype and va.tobytes() == vb.tobytes(), name
    for name in ("runs.csv", "runs.json", "summary.json"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_in_process_a_local_cluster_and_a_scheduler_give_identical_tables(
    scheduler: DaskProcesses,
    reference: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """In-process (one chunk of 300), LocalCluster of 2 (chunks of 40), the scheduler through
    the command with --json (chunks of 7 and auto): the same table, and --json's stdout is
    exactly one JSON object."""
    assert _table(reference).column("diverged").to_numpy().sum() == 42
    local = run_sweep(replace(STUDY, chunk=40), ROBOT, TRAJECTORY, tmp_path / "local", plot=False, workers=2)
    assert local.engine.startswith("LocalCluster of 2 workers at tcp://127.0.0.1:") and local.chunk == 40
    assert len(list((tmp_path / "local" / "runs").glob("part-*.parquet"))) == 8
    assert_identical(reference, tmp_path / "local")
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # the bar shows on a terminal only
    for chunk in ("7", "auto"):
        argv = [
            "sweep",
            "pd",
            "--samples",
            "300",
            "--seed",
            "11",
            "--q0-spread",
            "0.2",
            "--param-error",
            "0.3",
        ]
        argv += ["--gain", "kp=100:400", "--gain", "kd=40:600", "--duration", "0.5", "--dt", "0.002"]
        argv += ["--scheduler", scheduler.address, "--chunk", chunk, "--json", "--no-plot"]
        out = tmp_path / f"scheduler-{chunk}"
        assert cmd_sweep(build_parser().parse_args([*argv, "--out", str(out)])) == 0
        captured = capsys.readouterr()
        payload = json.loads(captured.out)  # the whole of stdout: one JSON document
        assert payload["engine"] == f"scheduler {scheduler.address}" and payload["diverged"] == 42
        assert payload["chunk"] == (7 if chunk == "7" else 150)  # auto: 300 runs, 2 workers -> 2 of 150
        assert "300/300" in captured.err  # the progress display, on stderr
        assert_identical(reference, out)


def test_a_law_and_a_urdf_from_files_reach_workers_that_do_not_have_them(
    scheduler: DaskProcesses, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The law's file and the robot's URDF (not a catalog robot) are given by paths relative
    to the client's folder, which the workers (started elsewhere) cannot resolve: their text
    travels with the tasks."""
    law = (
        (ROOT / "examples" / "sliding_mode.py")
        .read_text()
        .replace('name = "sliding-mode"', 'name = "my-law"')
    )
    (tmp_path / "my_law.py").write_text(law)
    shutil.copy(ROOT / "robots" / "twolink.urdf", tmp_path / "my_arm.urdf")
    monkeypatch.chdir(tmp_path)
    robot = load_robot("my_arm.urdf", payload=0.3)
    assert robot.name == "my_arm"
    run = RunSpec(law="my_law.py:SlidingMode", simulation=SimulationConfig(duration=0.2))
    study = SweepConfig(run, samples=24, seed=2, q0_spread=0.1, chunk=5, gains=(GainRange("ks", 1.0, 5.0),))
    trajectory = default_trajectory(robot)
    run_sweep(study, robot, trajectory, "here", plot=False)
    for there in ("there", "again"):  # the same law in a second sweep on the same workers
        run_sweep(study, robot, trajectory, there, plot=False, scheduler=scheduler.address)
        assert (tmp_path / "here" / "runs.csv").read_bytes() == (tmp_path / there / "runs.csv").read_bytes()
    assert sorted(p.name for p in (scheduler.folder / "workers-cwd").iterdir()) == []


def test_a_sweep_on_the_mujoco_plant_runs_on_the_workers_as_in_process(
    scheduler: DaskProcesses, tmp_path: Path
) -> None:
    """``--plant mujoco`` with the arm's armature and dry friction: each worker builds the MuJoCo
    plant from the run's description (its own ``mujoco.batch``) and the table is the in-process one."""
    from twolink_pin.plant_options import PlantOptions

    run = RunSpec(
        law="pd",
        plant=PlantOptions(engine="mujoco", armature="arm", frictionloss="arm"),
        simulation=SimulationConfig(duration=0.2),
    )
    study = SweepConfig(run, samples=12, seed=3, q0_spread=0.1, chunk=5)
    run_sweep(study, ROBOT, TRAJECTORY, tmp_path / "here", plot=False)
    run_sweep(study, ROBOT, TRAJECTORY, tmp_path / "there", plot=False, scheduler=scheduler.address)
    assert_identical(tmp_path / "here", tmp_path / "there")


def test_a_robot_the_workers_would_rebuild_differently_is_refused(
    scheduler: DaskProcesses, tmp_path: Path
) -> None:
    """A twolink with another parameter map than its catalog profile's: a worker rebuilds the
    catalog twolink, whose digest differs; refused rather than computing another robot."""
    from twolink_pin.model.base_parameters import BaseParameterMap

    robot = load_robot("twolink", parameter_map=BaseParameterMap)
    with pytest.raises(ClusterError, match=r"its robot 'twolink' differs from the client's"):
        run_sweep(
            replace(STUDY, samples=10, chunk=5),
            robot,
            default_trajectory(robot),
            tmp_path / "o",
            scheduler=scheduler.address,
        )
    assert list(tmp_path.iterdir()) == []


def test_killing_a_worker_in_the_middle_of_its_task_still_gives_the_identical_table(tmp_path: Path) -> None:
    """Two workers without nanny (nothing restarts them); once the first runs are reported,
    the worker that is running a chunk is killed with SIGKILL. Dask reschedules its chunks on
    the other; the table equals the in-process one."""
    study = replace(
        STUDY, samples=240, chunk=30, run=replace(STUDY.run, simulation=SimulationConfig(duration=0.25))
    )
    run_sweep(study, ROBOT, TRAJECTORY, tmp_path / "reference", plot=False)
    processes = DaskProcesses(tmp_path, workers=2, nanny=False)
    try:
        processes.start()
        with processes.client() as client:
            pids = {pid: address for address, pid in client.run(os.getpid).items()}
            killed: list[int] = []
            seen: list[int] = []

            def progress(done: int, total: int) -> None:
                seen.append(done)
                if killed:
                    return
                busy = [address for address, keys in client.processing().items() if keys]
                pid = next((p for p, address in pids.items() if address in busy), None)
                if pid is not None:
                    os.kill(pid, signal.SIGKILL)
                    killed.append(pid)

            run_sweep(
                study,
                ROBOT,
                TRAJECTORY,
                tmp_path / "out",
                progress=progress,
                plot=False,
                scheduler=processes.address,
            )
            assert killed and seen[-1] == 240 and min(seen) < 240  # the kill landed mid-sweep
            victim = next(p for p in processes.workers if p.pid == killed[0])
            assert victim.wait(timeout=STARTUP) == -signal.SIGKILL
            _deadline_wait(lambda: len(client.scheduler_info()["workers"]) == 1, "the scheduler noticing")
    finally:
        processes.stop()
    assert_identical(tmp_path / "reference", tmp_path / "out")


def _sweep_process(out: Path, where: list[str]) -> subprocess.Popen[str]:
    argv = [TWOLINK_PIN, "sweep", "pd", "--samples", "4000", "--duration", "1", "--q0-spread", "0.1"]
    return subprocess.Popen(
        [*argv, "--chunk", "10", *where, "--out", str(out), "--no-plot"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _first_chunk_written(out: Path) -> bool:
    return bool(glob.glob(str(out.parent / f".{out.name}.partial-*" / "runs" / "part-*.parquet")))


def _sweep_tasks(scheduler: DaskProcesses) -> list[str]:
    with scheduler.client() as client:
        return client.run_on_scheduler(
            lambda dask_scheduler: [str(k) for k in dask_scheduler.tasks if str(k).startswith("sweep-")]
        )


def test_ctrl_c_cancels_the_tasks_on_the_scheduler_and_leaves_no_output(
    scheduler: DaskProcesses, tmp_path: Path
) -> None:
    out = tmp_path / "sweep"
    process = _sweep_process(out, ["--scheduler", scheduler.address])
    try:
        _deadline_wait(lambda: _first_chunk_written(out) or process.poll() is not None, "the first chunk")
        assert process.poll() is None and _sweep_tasks(scheduler)  # mid-sweep, tasks on the scheduler
        process.send_signal(signal.SIGINT)
        stdout, stderr = process.communicate(timeout=STARTUP)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130 and stdout == "", (process.returncode, stdout[-2000:], stderr[-2000:])
    assert stderr.rstrip().endswith("twolink-pin: interrupted")
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no folder, no staging folder
    _deadline_wait(lambda: not _sweep_tasks(scheduler), "the tasks' cancellation")


def test_sigterm_stops_a_local_cluster_and_leaves_no_process_and_no_output(tmp_path: Path) -> None:
    """The terminal's Ctrl-C reaches the whole process group; SIGTERM the client only: either
    way its LocalCluster's workers go with it."""
    out = tmp_path / "sweep"
    process = _sweep_process(out, ["--workers", "2"])
    try:
        _deadline_wait(lambda: _first_chunk_written(out) or process.poll() is not None, "the first chunk")
        children = psutil.Process(process.pid).children(recursive=True)
        assert process.poll() is None and len(children) >= 2
        process.send_signal(signal.SIGTERM)
        stdout, stderr = process.communicate(timeout=STARTUP)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 143 and stdout == ""
    assert stderr.rstrip().endswith("twolink-pin: terminated")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    _, alive = psutil.wait_procs(children, timeout=STARTUP)
    assert alive == []


def test_an_unreachable_scheduler_fails_fast_naming_its_address(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Nothing listens on port 1: refused at once, one line, exit 2, no folder."""
    code = main(
        ["sweep", "pd", "--samples", "3", "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path / "o")]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and err == [
        "twolink-pin: error: Dask cluster tcp://127.0.0.1:1: cannot be reached (Connection refused); start one "
        "with `dask scheduler` (see docs/cluster.md) or check the address"
    ]
    assert list(tmp_path.iterdir()) == []


def test_a_listener_that_is_no_scheduler_fails_within_the_timeout_naming_it(tmp_path: Path) -> None:
    """A socket that accepts and says nothing: the connection times out after --connect-timeout."""
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    accepted: list[socket.socket] = []
    thread = threading.Thread(target=lambda: accepted.append(server.accept()[0]), daemon=True)
    thread.start()
    try:
        with pytest.raises(
            ClusterError, match=rf"Dask cluster tcp://127\.0\.0\.1:{port}: cannot connect within 1 s"
        ):
            run_sweep(STUDY, ROBOT, TRAJECTORY, tmp_path / "o", scheduler=f"127.0.0.1:{port}", timeout=1.0)
    finally:
        server.close()
        for conn in accepted:
            conn.close()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--workers", "0"], "argument --workers: expected a whole number from 1 to 64, got '0'"),
        (["--workers", "two"], "argument --workers: expected a whole number, got 'two'"),
        (["--scheduler", "udp://h:1"], "argument --scheduler: expected tcp://HOST:PORT or tls://HOST:PORT"),
        (["--scheduler", "tcp://h:99999"], "got 'tcp://h:99999'"),
        (["--scheduler", "tcp://:8786"], "got 'tcp://:8786'"),
        (["--scheduler", "h:port"], "got 'h:port'"),
        (
            ["--workers", "2", "--scheduler", "h:1"],
            "argument --scheduler: not allowed with argument --workers",
        ),
        (["--chunk", "0"], "argument --chunk: expected a whole number from 1 to 100000, got '0'"),
    ],
)
def test_bad_cluster_options_are_one_line_naming_the_value(
    option: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main(["sweep", "pd", "--samples", "3", *option, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert info.value.code == 2 and len(err) == 1 and message in err[0]
    assert list(tmp_path.iterdir()) == []


def test_addresses_are_normalised() -> None:
    assert scheduler_address("10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert scheduler_address("tls://head.example.org") == "tls://head.example.org:8786"
    assert scheduler_address(" tcp://[::1]:9000 ") == "tcp://[::1]:9000"


def test_without_dask_the_command_says_how_to_install_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``distributed`` made unimportable: exit 1 with the install command; the library says it too."""
    monkeypatch.setitem(sys.modules, "distributed", None)
    assert not cluster_module.available()
    assert main(["sweep", "pd", "--samples", "3", "--workers", "2", "--out", str(tmp_path / "o")]) == 1
    assert capsys.readouterr().err.strip() == (
        "twolink-pin: error: --workers needs Dask, which is not installed: pip install 'twolink-pin[cluster]'"
    )
    with pytest.raises(ClusterError, match=r"pip install 'twolink-pin\[cluster\]'"):
        run_sweep(STUDY, ROBOT, TRAJECTORY, tmp_path / "o", workers=1)
    assert list(tmp_path.iterdir()) == []


def test_a_local_cluster_listens_on_localhost_only() -> None:
    """Every listening socket of this process and of its children (the LocalCluster's, and
    the module's scheduler and workers, started as docs/cluster.md says) is on 127.0.0.1."""
    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}
    with open_cluster(workers=1) as engine:
        assert engine.address.startswith("tcp://127.0.0.1:")
        processes = [me, *me.children(recursive=True)]
        assert len(processes) >= 2
        listening = [
            c.laddr
            for p in processes
            for c in p.net_connections(kind="inet")
            if c.status == psutil.CONN_LISTEN
        ]
        assert len(listening) >= 3 and {a.ip for a in listening} == {"127.0.0.1"}, listening
        children = [
            p for p in me.children(recursive=True) if p.pid not in before and not _resource_tracker(p)
        ]
    _, alive = psutil.wait_procs(children, timeout=STARTUP)
    assert alive == []


def _resource_tracker(process: psutil.Process) -> bool:
    """multiprocessing's resource tracker: one per parent process, started with its first
    spawned child and living as long as the parent (not the cluster's to stop)."""
    try:
        return "multiprocessing.resource_tracker" in " ".join(process.cmdline())
    except psutil.Error:
        return False


def test_a_worker_with_other_versions_is_refused(
    scheduler: DaskProcesses, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The client believes it runs another numpy: the first chunk back is refused, naming the
    worker and both versions; nothing is written."""
    real = sweep_module.environment()
    fake = tuple((name, "0.0-other" if name == "numpy" else version) for name, version in real)
    monkeypatch.setattr(sweep_module, "environment", lambda: fake)
    with pytest.raises(
        ClusterError,
        match=r"Dask cluster tcp://127\.0\.0\.1:\d+: runs twolink-pin .*numpy 2\.[^,]*, .* but the client .*numpy 0\.0-other",
    ):
        run_sweep(
            replace(STUDY, samples=20, chunk=10),
            ROBOT,
            TRAJECTORY,
            tmp_path / "o",
            scheduler=scheduler.address,
        )
    assert list(tmp_path.iterdir()) == []


CRASHING_LAW = """
import os, signal
from twolink_pin.controllers import PDFeedforward

class CrashOnWorker(PDFeedforward):
    name = "crash-on-worker"

    def compute(self, x, terms):
        try:
            from distributed import get_worker
            get_worker()
        except (ImportError, ValueError):
            return super().compute(x, terms)
        os.kill(os.getpid(), signal.SIGKILL)  # the worker process dies in its task
"""


def test_a_chunk_that_keeps_killing_its_workers_fails_the_sweep_naming_it(
    scheduler: DaskProcesses, tmp_path: Path
) -> None:
    """A law that kills the worker process running it, with the scheduler allowing no retry
    (Dask's allowed-failures, 3 by default, set to 0 here): the failed run it is, naming the
    law, its runs and the last worker (exit status 1; it was a ClusterError without the law);
    the nannies restart the workers; nothing is written. Both chunks (of 2 runs, one per
    worker) crash: the one whose KilledWorker reaches the client first is named."""
    (tmp_path / "crash.py").write_text(CRASHING_LAW)
    study = SweepConfig(
        RunSpec(law=f"{tmp_path}/crash.py:CrashOnWorker", simulation=SimulationConfig(duration=0.1)),
        samples=4,
    )
    with scheduler.client() as client:
        client.run_on_scheduler(lambda dask_scheduler: setattr(dask_scheduler, "allowed_failures", 0))
        try:
            with pytest.raises(
                ControllerError,
                match=r"controller 'crash-on-worker' failed: runs (0–1|2–3) killed 1 Dask worker process in a row: the "
                r"law CrashOnWorker ended them .*; the last was tcp://127\.0\.0\.1:\d+: see its log",
            ):
                run_sweep(study, ROBOT, TRAJECTORY, tmp_path / "o", scheduler=scheduler.address)
        finally:
            client.run_on_scheduler(lambda dask_scheduler: setattr(dask_scheduler, "allowed_failures", 3))
            client.wait_for_workers(2, timeout=STARTUP)
    assert not (tmp_path / "o").exists()


def test_the_benchmark_reports_sweep_throughput_in_process_and_on_1_and_2_workers() -> None:
    """Smoke test of ``scripts/benchmark.py --sweep-only --quick``: positive runs/s for each
    robot and mode, the ratio, and the client's memory (no timing asserted)."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "benchmark.py"), "--sweep-only", "--quick", "--json"],
        capture_output=True,
        text=True,
        check=True,
        timeout=600,
    )
    results = json.loads(done.stdout.splitlines()[-1])
    rows = results["sweep_throughput"]
    assert [r["robot"] for r in rows] == ["twolink", "ur5"]
    for row in rows:
        assert all(row[mode] > 0 for mode in ("in_process", "1w", "2w"))
        assert row["speedup"] == row["2w"] / row["1w"]
    assert set(results["sweep_speedup_from"]) == {"twolink", "ur5"}
    memory = results["client_memory"]
    assert [(m["samples"], m["workers"]) for m in memory] == [(500, 0), (500, 2)]
    assert all(m["rss_peak_mib"] >= m["rss_before_mib"] > 0 for m in memory)
    assert "2 workers reach 1.6x the 1-worker throughput" in done.stdout
