"""``tune``'s server side without a browser: where it may listen, where the page may write,
a law that never returns, and ``--watch`` after the law's ``Gains`` changed. Real servers on
127.0.0.1; every wait is on a signal (an event, a queue) with a generous bound."""

from __future__ import annotations

import queue
import socket
import threading
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from twolink_pin.errors import InvalidParameterError
from twolink_pin.run_spec import RunSpec
from twolink_pin.simulation import SimulationConfig
from twolink_pin.tuning.address import check_listen
from twolink_pin.tuning.latest import LatestWins, RunTooLong
from twolink_pin.tuning.outputs import page_path

WAIT = 60.0
"""Bound on every wait [s]: a failure, never a pass, when it runs out."""


# --- where the page is served ---------------------------------------------------------


def test_a_host_that_does_not_resolve_is_refused_naming_it() -> None:
    with pytest.raises(InvalidParameterError, match=r"--host = 'nohost\.invalid'.*does not resolve"):
        check_listen("nohost.invalid")


def test_an_address_no_interface_has_is_refused_naming_it() -> None:
    with pytest.raises(
        InvalidParameterError, match=r"--host = '192\.0\.2\.1'.*cannot listen on 192\.0\.2\.1"
    ):
        check_listen("192.0.2.1")


def test_a_port_in_use_is_refused_naming_it() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        with pytest.raises(InvalidParameterError, match=rf"--port = {port} .*in use"):
            check_listen("127.0.0.1", port)


def test_loopback_is_told_apart_from_every_interface() -> None:
    assert check_listen("127.0.0.1").loopback
    assert not check_listen("0.0.0.0").loopback


@pytest.mark.parametrize(
    ("host", "why"),
    [
        ("224.0.0.1", "224.0.0.1 is a multicast address"),
        ("239.1.2.3", "239.1.2.3 is a multicast address"),
        ("ff02::1", "ff02::1 is a multicast address"),
        ("255.255.255.255", "255.255.255.255 is the broadcast address"),
        # the loopback network's broadcast: Linux binds it and nothing connects (elsewhere: no bind)
        ("127.255.255.255", "(nothing can connect to|cannot listen on) 127.255.255.255"),
    ],
)
def test_a_multicast_or_broadcast_host_is_refused(host: str, why: str) -> None:
    """Linux lets a TCP socket bind and listen on these (the page "served", and no browser
    could reach it): refused, naming the address and why."""
    with pytest.raises(InvalidParameterError, match=rf"--host = '{host}' is invalid: .*{why}"):
        check_listen(host)


def test_tune_on_a_broadcast_address_is_one_line_and_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    from twolink_pin.cli import main

    assert main(["tune", "pd", "--host", "255.255.255.255", "--no-browser", "--duration", "0.1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "broadcast address" in err and "Traceback" not in err


# --- where the page writes ------------------------------------------------------------


def test_a_name_inside_the_folder_is_the_file_there(tmp_path: Path) -> None:
    assert page_path(tmp_path, "runs/a.npz", ".npz", "run file") == tmp_path.resolve() / "runs" / "a.npz"


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("/tmp/elsewhere.npz", "an absolute path is refused"),
        ("../up.npz", "'..' is refused"),
        ("a/../../up.npz", "'..' is refused"),
        ("~/home.npz", "an absolute path is refused"),
        ("run.txt", "ending in .npz"),
        ("", "ending in .npz"),
        ("out/run.npz", "outside the folder"),  # out is a symbolic link to a folder elsewhere
    ],
)
def test_a_name_that_leaves_the_folder_is_refused_naming_it(tmp_path: Path, text: str, why: str) -> None:
    folder, elsewhere = tmp_path / "tuner", tmp_path / "elsewhere"
    folder.mkdir()
    elsewhere.mkdir()
    (folder / "out").symlink_to(elsewhere)
    with pytest.raises(InvalidParameterError, match="run file") as raised:
        page_path(folder, text, ".npz", "run file")
    assert why in str(raised.value) and repr(text) in str(raised.value)


# --- a run that does not stop ---------------------------------------------------------


def test_a_superseded_run_that_never_returns_is_left_behind_and_the_newer_one_runs() -> None:
    """Run 1 loops in Python and never asks whether it is superseded: 0.2 s after request 2
    it is left behind, request 2 runs and is delivered, and the loop is stopped by the
    exception raised in its thread (the thread ends)."""
    looping, abandoned = threading.Event(), queue.Queue[tuple[int, float]]()
    delivered: queue.Queue[tuple[int, object]] = queue.Queue()
    threads: list[threading.Thread] = []

    def work(x: int) -> int:
        if x == 1:
            threads.append(threading.current_thread())
            looping.set()
            while True:  # a law's busy loop
                pass
        return 10 * x

    session: LatestWins[int, int] = LatestWins(
        work,
        lambda g, r, out: delivered.put((g, out)),
        stuck_after=0.2,
        on_abandoned=lambda g, s: abandoned.put((g, s)),
    )
    try:
        session.submit(1)
        assert looping.wait(WAIT)
        session.submit(2)
        assert delivered.get(timeout=WAIT) == (2, 20)
        generation, seconds = abandoned.get(timeout=WAIT)
        assert generation == 1 and seconds >= 0.2  # it ran at least as long as it was superseded
        threads[0].join(WAIT)
        assert not threads[0].is_alive()
        assert session.idle(WAIT) and session.abandoned == 1 and session.runs == 2
        assert delivered.empty()
    finally:
        session.close()


def test_a_run_past_the_limit_is_delivered_as_too_long_and_the_next_one_runs() -> None:
    release = threading.Event()
    delivered: queue.Queue[tuple[int, object]] = queue.Queue()

    def work(x: int) -> int:
        if x == 1:
            release.wait(WAIT)  # a law that sleeps
        return 10 * x

    session: LatestWins[int, int] = LatestWins(work, lambda g, r, out: delivered.put((g, out)), limit=0.2)
    try:
        session.submit(1)
        generation, outcome = delivered.get(timeout=WAIT)
        assert generation == 1 and isinstance(outcome, RunTooLong)
        assert "no progress for --timeout 0.2 s" in str(outcome)
        session.submit(2)
        assert delivered.get(timeout=WAIT) == (2, 20)
    finally:
        release.set()
        session.close()
    assert delivered.empty()  # run 1, released at last, is never delivered


def test_a_run_that_makes_progress_is_not_cut_by_the_limit() -> None:
    """The limit counts from the last sign of progress: a run of 0.6 s that reports progress
    every 0.05 s under a 0.2-s limit is delivered whole."""
    import time

    delivered: queue.Queue[tuple[int, object]] = queue.Queue()
    session: LatestWins[int, int] | None = None

    def work(x: int) -> int:
        for _ in range(12):
            time.sleep(0.05)  # a block of samples
            assert session is not None
            session.alive()
        return 10 * x

    session = LatestWins(work, lambda g, r, out: delivered.put((g, out)), limit=0.2)
    try:
        session.submit(1)
        assert delivered.get(timeout=WAIT) == (1, 10)
        assert session.abandoned == 0
    finally:
        session.close()


def _tuner(
    law: Any, duration: float, folder: Path | None = None, **kw: Any
) -> tuple[Any, queue.Queue[dict[str, Any]]]:
    from twolink_pin.cli.simulate_line import command_line, simulate_argv
    from twolink_pin.model import load_robot
    from twolink_pin.trajectory import default_trajectory
    from twolink_pin.tuning import Tuner

    robot = load_robot("twolink")
    reference = default_trajectory(robot)
    lines: queue.Queue[dict[str, Any]] = queue.Queue()
    tuner = Tuner(
        RunSpec(law=law, simulation=SimulationConfig(duration=duration)),
        0.0,
        lambda payload: (robot, reference),
        lambda spec, payload: (
            command_line(simulate_argv(spec, None, payload)) if isinstance(spec.law, str) else ""
        ),
        lambda spec, payload: {"law": str(spec.law)},
        lines.put,
        folder=folder,
        **kw,
    )
    return tuner, lines


def test_a_law_that_sleeps_does_not_hold_a_change_back_and_the_page_says_so() -> None:
    """The first run's law sleeps (until the test ends); kd × 1.5 is asked for: the page says
    run 1 cannot be stopped and run 2 is shown with the new gains."""
    from twolink_pin.controllers.pd import PDFeedforward

    asleep, release = threading.Event(), threading.Event()

    class SleepingPD(PDFeedforward):
        def compute(self, x, terms):  # type: ignore[no-untyped-def]
            if not asleep.is_set():
                asleep.set()
                release.wait(WAIT)  # the first call of the first run only
            return super().compute(x, terms)

    tuner, lines = _tuner(SleepingPD, 0.2, stuck_after=0.2)
    try:
        assert asleep.wait(WAIT)
        tuner.panel.sliders[-1].value = 1.5  # kd × (all)
        tuner.changed()
        line = lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        status = tuner.status.content
    finally:
        release.set()
        tuner.close()
    assert line["run"] == 2 and line["gains"]["kd"] == [60.0, 75.0]
    assert status.startswith("run 2: 0.2 s simulated") and "run 1 cannot be stopped" in status
    assert tuner.session.abandoned == 1


# --- what the page writes -------------------------------------------------------------


class _Page:
    """A page's client handle: the downloads it was offered."""

    def __init__(self) -> None:
        self.files: list[tuple[str, bytes]] = []

    def send_file_download(self, name: str, content: bytes, *args: Any, **kw: Any) -> None:
        self.files.append((name, content))


def test_save_and_export_write_inside_the_folder_offer_downloads_and_refuse_other_paths(
    tmp_path: Path,
) -> None:
    """The saved run, loaded back from the downloaded bytes, is the run shown (t, q, τ);
    the animation download is the file written; an absolute path and a ``..`` write nothing."""
    import io

    from twolink_pin.simulation.storage import load_result

    outside = tmp_path / "outside.npz"
    folder = tmp_path / "tuner"
    folder.mkdir()
    tuner, lines = _tuner("pd", 0.2, folder=folder)
    page = _Page()
    try:
        lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        shown = tuner._latest.result  # the run on screen
        files = tuner.files  # the folder "as a command"
        for refused in (str(outside), "../outside.npz"):
            files.save_path.value = refused
            files.save(page)  # the button's handler
            assert files.saved.content.startswith("**not saved**") and refused in files.saved.content
        files.save_path.value = "runs/kept.npz"
        files.save(page)
        files.html_path.value = "arm.html"
        files.export(page)
    finally:
        tuner.close()
    assert not outside.exists() and sorted(p.name for p in folder.rglob("*")) == [
        "arm.html",
        "kept.npz",
        "runs",
    ]
    assert [name for name, _ in page.files] == ["kept.npz", "arm.html"]
    assert page.files[0][1] == (folder / "runs" / "kept.npz").read_bytes()
    assert page.files[1][1] == (folder / "arm.html").read_bytes()
    downloaded = tmp_path / "downloaded.npz"
    downloaded.write_bytes(io.BytesIO(page.files[0][1]).getvalue())
    again = load_result(downloaded)
    for name in ("t", "q", "tau_command"):
        np.testing.assert_array_equal(getattr(again, name), getattr(shown, name))


# --- --watch --------------------------------------------------------------------------


def test_watch_says_when_the_gains_declaration_changed_and_the_line_still_reproduces(tmp_path: Path) -> None:
    """The law file's default of ``phi`` and its compute change while the tuner watches it: the
    page says it kept the old controls (naming the changed default), and the reloaded run's
    command line, run as ``simulate`` would, gives the metrics shown, float for float."""
    import os
    import shlex

    from twolink_pin.cli.commands.common import run_spec
    from twolink_pin.cli.output import jsonable
    from twolink_pin.cli.parser import build_parser
    from twolink_pin.metrics import compute_metrics
    from twolink_pin.model import load_robot
    from twolink_pin.simulation import simulate
    from twolink_pin.trajectory import default_trajectory

    source = (Path(__file__).resolve().parents[1] / "examples" / "sliding_mode.py").read_text()
    law = tmp_path / "watched_law.py"
    law.write_text(source.replace('name = "sliding-mode"', 'name = "sliding-mode-watched-2"'))
    tuner, lines = _tuner(f"{law}:SlidingMode", 0.2, folder=tmp_path, watch=True)
    try:
        first = lines.get(timeout=WAIT)
        text = law.read_text()
        assert "phi: Any = gain(0.05" in text and "return LawOutput(tau - g.k * s" in text
        stamp = law.stat()
        law.write_text(
            text.replace("phi: Any = gain(0.05", "phi: Any = gain(0.07").replace(
                "return LawOutput(tau - g.k * s", "return LawOutput(tau - 2.0 * g.k * s"
            )
        )
        os.utime(law, ns=(stamp.st_atime_ns, stamp.st_mtime_ns + 10**9))  # a new time on a coarse clock
        line = lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        status = tuner.status.content
    finally:
        tuner.close()
    assert "the law's Gains changed" in status and "'phi [rad/s]' default 0.07 (was 0.05)" in status
    assert line["metrics"] != first["metrics"]
    args = build_parser().parse_args(shlex.split(str(line["command"]))[1:])
    spec = run_spec(args, args.controller)
    robot = load_robot("twolink")
    result = simulate(*spec.build(robot), default_trajectory(robot), spec.simulation)
    assert jsonable(compute_metrics(result).as_dict()) == jsonable(line["metrics"])


def test_the_default_run_holds_three_periods_as_help_says(capsys: pytest.CaptureFixture[str]) -> None:
    """No ``--duration``: three periods of the robot's reference (the last period's error then
    differs from the whole run's), and ``--help`` says so, not simulate's 30 s."""
    from twolink_pin.cli.commands.tune import PERIODS, _duration
    from twolink_pin.cli.parser import build_parser
    from twolink_pin.model import load_robot
    from twolink_pin.trajectory import default_trajectory

    parser = build_parser()
    args = parser.parse_args(["tune", "pd"])
    _duration(args)
    assert PERIODS == 3 and args.duration == 3 * default_trajectory(load_robot("twolink")).period
    with pytest.raises(SystemExit):
        parser.parse_args(["tune", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "default: 3 periods of the reference" in text and "(default 30)" not in text


# --- numbers typed into the page's boxes (what the script sends, without a page) --------


def test_typed_numbers_reach_the_run_settings_the_plant_and_the_playback_or_are_refused_there() -> None:
    """The script's messages, as a page sends them: "2" into ``periods`` runs two periods;
    "-1" into ``delay [steps]`` and "0" into the playback's speed are refused beside them,
    naming what is expected, and nothing runs; "2e0" into the speed plays twice as fast."""
    import json

    tuner, lines = _tuner("pd", 0.2)
    try:
        lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        channel = tuner.panel.channel

        def typed(n: int, label: str, text: str) -> None:
            channel.received(json.dumps({"page": "p", "items": [[n, label, 0, text]]}))

        typed(1, "periods", "2")
        line = lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        typed(2, "delay [steps]", "-1")
        typed(3, "speed", "0")
        refused_speed = tuner.scene.note.content
        typed(4, "speed", "2e0")
        plant_note, speed_note = tuner.panel.plant.error.content, tuner.scene.note.content
        speed = float(tuner.scene.speed.value)
        generation = tuner.session.generation
    finally:
        tuner.close()
    assert line["spec"]["simulation"]["duration"] == 8.0  # two 4-s periods of the twolink's reference
    assert plant_note.startswith(
        "**refused**: delay [steps] = '-1' is invalid: expected a whole number from 0 to"
    )
    assert refused_speed == "**refused**: speed = '0' is invalid: expected a number > 0"
    assert speed_note == "" and speed == 2.0  # then "2e0" taken
    assert generation == 2  # the refused values ran nothing; the speed is the playback's


def test_the_plant_folders_engine_runs_the_arm_on_mujoco_and_its_line_says_so() -> None:
    """The engine menu (the plant's folder) set to mujoco: the run and its command line are
    MuJoCo's (``--plant mujoco``), as ``simulate`` would run it."""
    tuner, lines = _tuner("pd", 0.2)
    try:
        lines.get(timeout=WAIT)
        assert tuner.session.idle(WAIT)
        assert tuple(tuner.panel.plant.engine.options) == ("pinocchio", "mujoco")
        tuner.panel.plant.engine.value = "mujoco"
        tuner.changed()
        line = lines.get(timeout=WAIT)
    finally:
        tuner.close()
    assert "error" not in line, line
    assert line["spec"]["plant"]["engine"] == "mujoco" and "--plant=mujoco" in line["command"]
