"""How a corpus case runs and what every case must meet.

:func:`prepare` builds the case folder from its setup steps, :func:`run` runs the command
(in this process, or as a real process in one of the ways of :data:`spec.RUNNERS`) and
:func:`verify` returns the broken expectations — the case's own and the invariants of every
case:

* no Python traceback on stderr (``Traceback (most recent call last)``), no uncaught exception;
* no hang: the command ends within the case's timeout;
* a failed command (exit != 0) prints exactly one line on stderr besides tqdm progress lines
  (cleanly ended), it is the last line, starts with ``twolink-pin``, is at most
  :data:`MAX_ERROR_LINE` characters, and stdout stays empty (exit 1 or 2);
* a successful command prints nothing on stderr but progress, and no ``nan`` / ``inf``
  on stdout;
* every file present after the setup is byte-identical afterwards (except ``Case.changed``),
  and no staging leftover (``.*.partial-*``, ``.*.tmp``, ``.*.old-*``) remains anywhere;
* a real process leaves no process behind (every process that inherited the case's marker
  in its environment is gone).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import shutil
import signal
import socket
import stat
import subprocess
import sys
import tempfile
import time
import traceback
import uuid
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from corpus import spec
from corpus.spec import Case

MAX_ERROR_LINE = 1000
"""Longest acceptable error line [characters]."""
PROGRESS = re.compile(r"\d+%\|.*\|\s*\d+/\d+ \[")
"""A tqdm progress line."""
NONFINITE = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])", re.IGNORECASE)
"""A non-finite number as Python, numpy or JSON print it."""
STAGING = re.compile(r"^\..*(\.partial-|\.tmp$|\.old-\d+)")
"""Hidden staging files and folders of the library's atomic writers."""
TRACEBACK = "Traceback (most recent call last)"
MARK = "TWOLINK_CORPUS_MARK"
"""Environment variable carrying a per-case token into every process the case starts."""
DROPPED_CAPS = "-dac_override,-dac_read_search,-fowner"
HANG_SCALE = 3.0
"""A case's ``timeout`` is what it needs on a quiet machine; the runner waits this many
times longer before calling it a hang, so that a machine busy with other work (CI, two
CPU-bound processes beside the suite) does not fail the suite. A hang is a hang either way."""
SIGNAL_GRACE = 30.0
"""How long a signalled process (and its workers) may take to clean up and end [s]: a bound
against a hang, not a speed requirement."""
REAP_GRACE = 15.0
"""How long after a command ended the processes it started may take to be gone [s]."""
READY = "TWOLINK_PIN_READY_FILE"
"""Environment variable naming the file where the program writes the stages it reaches."""

FULLFS_SCRIPT = r"""
mount -t tmpfs -o size=32k,mode=0777 tmpfs "$1" || exit 97
if [ "$2" = 1 ]; then dd if=/dev/zero of="$1/filler" bs=1k 2>/dev/null; fi
listing=$3; root=$1; shift 3
"$@"
rc=$?
find "$root" -mindepth 1 > "$listing"
exit $rc
"""
DEV_SCRIPT = r"""
mount -t tmpfs -o size=1m,mode=0755 tmpfs /dev || exit 97
mknod -m 666 /dev/null c 1 3; mknod -m 666 /dev/zero c 1 5; mknod -m 666 /dev/full c 1 7
mknod -m 666 /dev/random c 1 8; mknod -m 666 /dev/urandom c 1 9
ln -s /proc/self/fd /dev/fd; ln -s /proc/self/fd/0 /dev/stdin
ln -s /proc/self/fd/1 /dev/stdout; ln -s /proc/self/fd/2 /dev/stderr
mkdir /dev/shm && mount -t tmpfs tmpfs /dev/shm
listing=$1; shift
"$@"
rc=$?
for f in /dev/null /dev/zero /dev/full; do printf '%s|%s\n' "$f" "$(stat -c %F "$f" 2>&1)"; done > "$listing"
ls -A /dev >> "$listing"
exit $rc
"""
DEV_NAMES = {"null", "zero", "full", "random", "urandom", "fd", "stdin", "stdout", "stderr", "shm"}


class CaseTimeout(BaseException):
    """Raised by the alarm in an in-process run that takes too long."""


class SetupError(Exception):
    """A setup step failed: the case itself is broken."""


@dataclass
class Outcome:
    """What a run did."""

    code: int | None
    stdout: str
    stderr: str
    seconds: float
    timed_out: bool = False
    notes: list[str] = field(default_factory=list)
    """Problems the runner saw itself (leftover processes, a full disk left dirty, ...)."""


@dataclass
class Context:
    """What a prepared case holds while it runs."""

    folder: Path
    harness: Path
    keep: list[Any] = field(default_factory=list)
    port: int | None = None

    def close(self) -> None:
        for obj in self.keep:
            with contextlib.suppress(Exception):
                obj.close()


# -- capabilities of this machine ----------------------------------------------------------------


_probe: dict[str, str | None] = {}


def unavailable(runner: str) -> str | None:
    """Why ``runner`` cannot work here (None: it can)."""
    if runner in _probe:
        return _probe[runner]
    reason: str | None = None
    if runner == "setpriv" and os.geteuid() == 0:
        with tempfile.TemporaryDirectory() as tmp:
            ro = Path(tmp) / "ro"
            ro.mkdir()
            ro.chmod(0o555)
            if shutil.which("setpriv") is None:
                reason = "setpriv is not installed"
            else:
                r = subprocess.run(
                    ["setpriv", f"--bounding-set={DROPPED_CAPS}", "--", "sh", "-c", f"echo > {ro}/x"],
                    capture_output=True,
                )
                if r.returncode == 0:
                    reason = "dropping CAP_DAC_OVERRIDE does not make root obey a 0555 folder here"
    elif runner in ("fullfs", "fullfs-filled", "devsandbox"):
        if shutil.which("unshare") is None:
            reason = "unshare is not installed"
        else:
            r = subprocess.run(
                ["unshare", "-m", "sh", "-c", "mount -t tmpfs -o size=64k tmpfs /mnt"], capture_output=True
            )
            if r.returncode != 0:
                reason = f"cannot mount a tmpfs in a private mount namespace ({r.stderr.decode().strip()})"
    _probe[runner] = reason
    return reason


# -- setup ---------------------------------------------------------------------------------------


def prepare(case: Case, root: Path, capfd: Any) -> Context:
    """Build the case folder ``root/case`` from the setup steps."""
    folder = root / "case"
    harness = root / "harness"
    folder.mkdir()
    harness.mkdir()
    ctx = Context(folder, harness)
    if "{port}" in " ".join(a for a in case.argv if isinstance(a, str)):
        sock = socket.socket()
        sock.bind(("127.0.0.1", 0))
        sock.listen(1)
        ctx.keep.append(sock)
        ctx.port = sock.getsockname()[1]
    if case.run in ("fullfs", "fullfs-filled"):
        (folder / "full").mkdir()
    for step in case.setup:
        try:
            _step(step, folder, ctx, capfd)
        except SetupError:
            raise
        except Exception as exc:
            raise SetupError(
                f"setup step {step.kind} {step.path!r} failed: {type(exc).__name__}: {exc}"
            ) from exc
    return ctx


def _step(step: spec.Step, folder: Path, ctx: Context, capfd: Any) -> None:
    path = folder / step.path if step.path else folder
    if step.kind not in ("cli", "chmod", "truncate", "symlink"):
        path.parent.mkdir(parents=True, exist_ok=True)
    if step.kind == "text":
        path.write_text(step.arg, encoding="utf-8")
    elif step.kind == "blob":
        content = step.arg(folder) if callable(step.arg) else step.arg
        path.write_bytes(content)
    elif step.kind == "copy":
        shutil.copyfile(step.arg, path)
    elif step.kind == "twolink":
        import twolink_pin

        body = twolink_pin.twolink_urdf_path().read_text(encoding="utf-8")
        for old, new in step.arg:
            if old not in body:
                raise SetupError(f"twolink.urdf has no {old!r} to replace")
            body = body.replace(old, new, 1)
        path.write_text(body, encoding="utf-8")
    elif step.kind == "folder":
        path.mkdir(parents=True, exist_ok=True)
    elif step.kind == "fifo":
        os.mkfifo(path)
    elif step.kind == "device":
        numbers = {"null": (1, 3), "zero": (1, 5), "full": (1, 7)}[step.arg]
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(*numbers))
    elif step.kind == "socket":
        sock = socket.socket(socket.AF_UNIX)
        here = os.getcwd()
        os.chdir(path.parent)  # a relative name: AF_UNIX paths are limited to 108 bytes
        try:
            sock.bind(path.name)
        finally:
            os.chdir(here)
        ctx.keep.append(sock)
    elif step.kind == "cli":
        argv = [_substitute(a, ctx) for a in step.arg]
        code, _, err = _inproc_main(argv, folder, 600.0, capfd)
        if code != 0:
            raise SetupError(f"setup run twolink-pin {' '.join(argv)} exited {code}: {err.strip()[-300:]}")
    elif step.kind == "chmod":
        os.chmod(path, step.arg)
    elif step.kind == "symlink":
        os.symlink(step.arg, path)
    elif step.kind == "truncate":
        os.truncate(path, step.arg)
    else:
        raise SetupError(f"unknown setup step {step.kind!r}")


def _substitute(arg: str | bytes, ctx: Context) -> Any:
    if isinstance(arg, bytes):
        return arg
    return (
        arg.replace("{corpus}", str(spec.CORPUS))
        .replace("{dir}", str(ctx.folder))
        .replace("{port}", str(ctx.port))
    )


# -- snapshots -----------------------------------------------------------------------------------


def snapshot(folder: Path) -> dict[str, tuple[str, str]]:
    """Every entry below ``folder``: relative path → (type, sha256 of a regular file's content)."""
    entries: dict[str, tuple[str, str]] = {}
    for top, dirs, files in os.walk(folder):
        for name in dirs + files:
            full = Path(top) / name
            rel = str(full.relative_to(folder))
            info = os.lstat(full)
            mode = info.st_mode
            if stat.S_ISREG(mode):
                digest = hashlib.sha256()
                with open(full, "rb") as f:
                    for block in iter(lambda: f.read(2**20), b""):
                        digest.update(block)
                entries[rel] = ("file", digest.hexdigest())
            elif stat.S_ISLNK(mode):
                entries[rel] = ("link", os.readlink(full))
            elif stat.S_ISDIR(mode):
                entries[rel] = ("dir", "")
            elif stat.S_ISFIFO(mode):
                entries[rel] = ("fifo", "")
            elif stat.S_ISCHR(mode):
                entries[rel] = ("chardev", str(info.st_rdev))
            elif stat.S_ISSOCK(mode):
                entries[rel] = ("socket", "")
            else:
                entries[rel] = ("other", "")
    return entries


# -- running -------------------------------------------------------------------------------------


def _on_alarm(signum: int, frame: object) -> None:
    raise CaseTimeout


def _inproc_main(argv: list[str], cwd: Path, timeout: float, capfd: Any) -> tuple[int | None, str, str]:
    """``twolink_pin.cli.main(argv)`` in ``cwd`` with an alarm; returns (code, stdout, stderr).

    An uncaught exception is appended to stderr as Python would print it (code 1); a
    timeout gives code None.
    """
    from twolink_pin.cli import main

    capfd.readouterr()
    here = os.getcwd()
    saved = {s: signal.getsignal(s) for s in (signal.SIGTERM, signal.SIGINT, signal.SIGALRM)}
    code: int | None = None
    extra = ""
    os.chdir(cwd)
    signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    try:
        with warnings.catch_warnings():
            _console_warnings()
            code = main(list(argv))
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            code = exc.code or 0
        else:
            extra, code = f"{exc.code}\n", 1
    except CaseTimeout:
        code = None
    except BaseException:
        extra, code = traceback.format_exc(), 1
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        for s, handler in saved.items():
            signal.signal(s, handler)
        os.chdir(here)
    out, err = capfd.readouterr()
    return code, out, err + extra


def _console_warnings() -> None:
    """Warnings as ``python -m twolink_pin.cli`` shows them: Python's default filters, printed on stderr."""
    warnings.resetwarnings()
    warnings.simplefilter("default")
    for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
        warnings.filterwarnings("ignore", category=category)

    def show(
        message: Any, category: Any, filename: str, lineno: int, file: Any = None, line: Any = None
    ) -> None:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))

    warnings.showwarning = show


def _env(token: str, case: Case, ctx: Context) -> dict[str, str]:
    env = dict(os.environ)
    env.update({MARK: token, "MPLBACKEND": "Agg", "PYTHONDONTWRITEBYTECODE": "1"})
    env.pop("PYTHONWARNINGS", None)
    for name, value in case.env:
        if value:
            env[name] = _substitute(value, ctx)
        else:
            env.pop(name, None)  # "" unsets
    return env


def _command(case: Case, argv: list[Any], ctx: Context) -> list[Any]:
    base = [sys.executable, "-m", "twolink_pin_entry", *argv]  # what the console script runs
    if case.run == "setpriv":
        return ["setpriv", f"--bounding-set={DROPPED_CAPS}", "--", *base] if os.geteuid() == 0 else base
    if case.run in ("fullfs", "fullfs-filled"):
        filled = "1" if case.run == "fullfs-filled" else "0"
        listing = str(ctx.harness / "listing")
        return [
            "unshare",
            "-m",
            "sh",
            "-c",
            FULLFS_SCRIPT,
            "sh",
            str(ctx.folder / "full"),
            filled,
            listing,
            *base,
        ]
    if case.run == "devsandbox":
        return ["unshare", "-m", "sh", "-c", DEV_SCRIPT, "sh", str(ctx.harness / "listing"), *base]
    if case.run == "stdout-closed":
        return ["sh", "-c", 'exec "$@" >&-', "sh", *base]
    if case.run == "stderr-closed":
        return ["sh", "-c", 'exec "$@" 2>&-', "sh", *base]
    return base


def _limit(memory: int | None) -> Any:
    """In the child before it starts: Ctrl-C's default disposition (the suite itself may run
    as a background job, whose children inherit an ignored SIGINT and would, by the Unix
    convention the program follows, keep ignoring it), and the memory limit if any."""

    def apply() -> None:
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        if memory is not None:
            import resource

            resource.setrlimit(resource.RLIMIT_AS, (memory, memory))

    return apply


def _marked(token: str) -> list[int]:
    """Processes whose environment carries ``token``."""
    found = []
    needle = f"{MARK}={token}".encode()
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as f:
                environ = f.read()
            with open(f"/proc/{entry}/stat", "rb") as f:
                state = f.read().rsplit(b")", 1)[-1].split()[0]
        except OSError:
            continue
        if needle in environ and state != b"Z":
            found.append(int(entry))
    return found


def _reap(token: str, outcome: Outcome, grace: float = REAP_GRACE) -> None:
    """Note and kill (by pid) the processes the case left behind."""
    deadline = time.monotonic() + grace
    left = _marked(token)
    while left and time.monotonic() < deadline:
        time.sleep(0.1)
        left = _marked(token)
    if left:
        names = []
        for pid in left:
            with contextlib.suppress(OSError):
                cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ")
                names.append(f"{pid} {cmdline[:80].decode(errors='replace')}")
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
        outcome.notes.append(f"left {len(left)} process(es) running {grace:g} s after it ended: {names}")


def run(case: Case, ctx: Context, capfd: Any) -> Outcome:
    """Run the case's command."""
    argv = [_substitute(a, ctx) for a in case.argv]
    cwd = ctx.folder / case.cwd
    start = time.monotonic()
    if case.run == "inproc":
        code, out, err = _inproc_main(argv, cwd, case.timeout * HANG_SCALE, capfd)
        return Outcome(code, out, err, time.monotonic() - start, timed_out=code is None)
    token = uuid.uuid4().hex
    cmd = _command(case, argv, ctx)
    with tempfile.TemporaryFile() as out_f, tempfile.TemporaryFile() as err_f:
        stdout: Any = out_f
        full = None
        if case.run == "stdout-full":
            full = open("/dev/full", "wb")  # closed below
            stdout = full
        stdin: Any = subprocess.PIPE if case.run == "stdin-pipe" else subprocess.DEVNULL
        ready = ctx.harness / "ready"
        env = _env(token, case, ctx)
        env[READY] = str(ready)
        proc = subprocess.Popen(
            cmd,
            cwd=cwd,
            env=env,
            stdin=stdin,
            stdout=stdout,
            stderr=err_f,
            start_new_session=True,
            preexec_fn=_limit(case.memory),
        )
        outcome = Outcome(None, "", "", 0.0)
        if case.run == "signal":
            _signal(case, proc, ready, outcome)
        else:
            try:
                proc.wait(timeout=case.timeout * HANG_SCALE)
            except subprocess.TimeoutExpired:
                outcome.timed_out = True
                with contextlib.suppress(OSError):
                    os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
        if proc.stdin is not None:
            proc.stdin.close()
        if full is not None:
            full.close()
        outcome.code = None if outcome.timed_out else proc.returncode
        outcome.seconds = time.monotonic() - start
        out_f.seek(0)
        err_f.seek(0)
        outcome.stdout = out_f.read().decode("utf-8", errors="replace")
        outcome.stderr = err_f.read().decode("utf-8", errors="replace")
    _reap(token, outcome)
    if case.run in ("fullfs", "fullfs-filled", "devsandbox") and outcome.code == 97:
        outcome.notes.append("the sandbox could not be set up (exit 97)")
    return outcome


def _wait_for_stage(proc: subprocess.Popen[bytes], ready: Path, stage: str, bound: float) -> bool:
    """Wait until the process has written ``stage`` to its readiness file (True) or has ended
    (False). ``bound`` [s] only guards against a program that never gets there (a hang)."""
    end = time.monotonic() + bound
    while time.monotonic() < end:
        with contextlib.suppress(OSError):
            if stage in ready.read_text().split():
                return True
        if proc.poll() is not None:
            return False
        time.sleep(0.01)  # polling a file, not a delay before the signal
    return False


def _signal(case: Case, proc: subprocess.Popen[bytes], ready: Path, outcome: Outcome) -> None:
    """Send ``case.signal`` as soon as the program says it reached the case's stage (its
    readiness file, :mod:`twolink_pin.readiness`); it must end, and its children with it."""
    import psutil

    assert case.signal is not None
    signum, stage, target = case.signal
    if not _wait_for_stage(proc, ready, stage, case.timeout * HANG_SCALE):
        if proc.poll() is None:
            outcome.notes.append(f"never reached the stage {stage!r} within {case.timeout * HANG_SCALE:g} s")
            with contextlib.suppress(OSError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        else:
            outcome.notes.append(
                f"ended by itself (exit {proc.returncode}) before reaching the stage {stage!r}"
            )
        return
    try:
        children = psutil.Process(proc.pid).children(recursive=True)
    except psutil.Error:
        children = []
    if target == "group":
        os.killpg(proc.pid, signum)
    else:
        proc.send_signal(signum)
    sent = time.monotonic()
    try:
        proc.wait(timeout=SIGNAL_GRACE)
    except subprocess.TimeoutExpired:
        outcome.notes.append(f"still running {SIGNAL_GRACE:g} s after {signal.Signals(signum).name}")
        with contextlib.suppress(OSError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    deadline = sent + SIGNAL_GRACE
    alive = [c for c in children if _alive(c)]
    while alive and time.monotonic() < deadline:
        time.sleep(0.1)
        alive = [c for c in alive if _alive(c)]
    if alive:
        outcome.notes.append(
            f"{len(alive)} worker process(es) of {len(children)} still running {SIGNAL_GRACE:g} s after "
            f"{signal.Signals(signum).name}: pids {[c.pid for c in alive]}"
        )
        for c in alive:
            with contextlib.suppress(Exception):
                c.kill()


def _alive(process: Any) -> bool:
    import psutil

    try:
        return bool(process.is_running() and process.status() != psutil.STATUS_ZOMBIE)
    except psutil.Error:
        return False


# -- verification --------------------------------------------------------------------------------


def visible_lines(text: str) -> list[str]:
    """The lines a terminal would show: per newline-ended line, what follows the last ``\\r``."""
    lines = []
    for raw in text.split("\n"):
        shown = raw.split("\r")[-1].strip()
        if shown:
            lines.append(shown)
    return lines


def _has(text: str, word: str) -> bool:
    low = text.lower()
    return any(alt.lower() in low for alt in word.split("|"))


def _under(rel: str, prefixes: tuple[str, ...]) -> bool:
    return any(rel == p or rel.startswith(p.rstrip("/") + "/") for p in prefixes)


def verify(case: Case, ctx: Context, before: dict[str, tuple[str, str]], outcome: Outcome) -> list[str]:
    """The expectations ``outcome`` breaks (empty: the case passes)."""
    problems: list[str] = list(outcome.notes)
    code, out, err = outcome.code, outcome.stdout, outcome.stderr
    if outcome.timed_out:
        problems.append(f"hang: still running after {case.timeout * HANG_SCALE:g} s")
    if TRACEBACK in err:
        problems.append(f"traceback: {last_line(err)}")
    if not outcome.timed_out and code not in case.exits:
        problems.append(f"exit {code}, expected {' or '.join(map(str, case.exits))}")
    lines = visible_lines(err)
    messages = [line for line in lines if not PROGRESS.search(line)]
    stdout_usable = case.run not in ("stdout-closed", "stdout-full")
    if code is not None and code > 0 and TRACEBACK not in err:  # < 0: killed, it could not say
        if not messages:
            if not (case.silent_ok or code < 0 or case.run == "stderr-closed"):
                problems.append("no error message on stderr")
        elif len(messages) > 1:
            shown = " / ".join(m[:160] for m in messages[:4])
            problems.append(f"stderr has {len(messages)} lines besides progress, expected 1: {shown}")
        else:
            line = messages[0]
            if lines[-1] != line:
                problems.append(f"the error is not the last stderr line: {lines[-1][:160]!r}")
            if not line.startswith("twolink-pin"):
                problems.append(f"the error line does not start with 'twolink-pin': {line[:160]!r}")
            if len(line) > MAX_ERROR_LINE:
                problems.append(f"the error line is {len(line)} characters (at most {MAX_ERROR_LINE})")
        if code in (1, 2) and stdout_usable and out.strip():
            problems.append(f"stdout not empty on failure: {out.strip()[:160]!r}")
    if code is not None and code != 0:
        missing = [w for w in (_substitute(w, ctx) for w in case.err) if not _has(err, w)]
        if missing:
            problems.append(f"stderr lacks {missing}: {last_line(err)[:300]!r}")
    if code == 0 and case.run != "signal":
        if messages and not case.warns:
            problems.append(f"success printed on stderr: {' / '.join(m[:160] for m in messages[:3])}")
        missing_warnings = [w for w in case.warns if not _has(err, w)]
        if missing_warnings:
            problems.append(f"stderr of the success lacks {missing_warnings}: {last_line(err)[:200]!r}")
        missing = [w for w in case.out if not _has(out, w)]
        if missing:
            problems.append(f"stdout lacks {missing}: {out.strip()[:200]!r}")
        if not case.nonfinite_ok and stdout_usable:
            hit = NONFINITE.search(out)
            if hit:
                s = max(0, hit.start() - 40)
                problems.append(f"non-finite value on stdout of a success: ...{out[s : hit.end() + 20]!r}")
    for word in case.not_err:
        if _has(err, word):
            problems.append(f"stderr says {word!r}: {last_line(err)[:200]!r}")
    problems += _files(case, ctx, before)
    problems += _sandbox(case, ctx)
    for check in case.checks:
        try:
            problem = CHECKS[check.kind](ctx, outcome, *check.args)
        except Exception as exc:
            problem = f"check {check.kind} failed: {type(exc).__name__}: {exc}"
        if problem:
            problems.append(problem)
    return problems


def last_line(text: str) -> str:
    """The last non-empty visible line of ``text``."""
    lines = visible_lines(text)
    return lines[-1] if lines else ""


def _files(case: Case, ctx: Context, before: dict[str, tuple[str, str]]) -> list[str]:
    problems = []
    after = snapshot(ctx.folder)
    for rel, entry in before.items():
        if _under(rel, case.changed):
            continue
        now = after.get(rel)
        if now is None:
            problems.append(f"deleted a file the user had: {rel}")
        elif now != entry:
            what = "replaced" if now[0] != entry[0] else "changed"
            problems.append(f"{what} a file the user had: {rel} ({entry[0]} -> {now[0]})")
    for rel in after:
        if STAGING.match(Path(rel).name) and rel not in before:
            problems.append(f"staging leftover: {rel}")
    for rel in case.exists:
        if not os.path.lexists(ctx.folder / rel):
            problems.append(f"missing afterwards: {rel}")
    for rel in case.absent:
        if os.path.lexists(ctx.folder / rel):
            problems.append(f"exists but must not: {rel}")
    for rel in case.chardev:
        path = Path(rel) if rel.startswith("/") else ctx.folder / rel
        try:
            if not stat.S_ISCHR(os.lstat(path).st_mode):
                problems.append(f"{rel} is no longer a character device")
        except OSError as exc:
            problems.append(f"{rel} is gone ({exc.strerror})")
    return problems


def _sandbox(case: Case, ctx: Context) -> list[str]:
    listing = ctx.harness / "listing"
    if case.run in ("fullfs", "fullfs-filled"):
        if not listing.exists():
            return ["the full-disk sandbox wrote no listing"]
        left = [Path(p).name for p in listing.read_text().split("\n") if p.strip()]
        left = [n for n in left if n != "filler"]
        return [f"left on the full disk: {left}"] if left else []
    if case.run == "devsandbox":
        if not listing.exists():
            return ["the /dev sandbox wrote no listing"]
        problems = []
        lines = listing.read_text().split("\n")
        for line in lines[:3]:
            name, _, kind = line.partition("|")
            if kind != "character special file":
                problems.append(f"{name} is no longer a character device ({kind})")
        extra = sorted(set(n for n in lines[3:] if n) - DEV_NAMES)
        if extra:
            problems.append(f"new entries in /dev: {extra}")
        return problems
    return []


# -- extra checks --------------------------------------------------------------------------------


def _json_source(ctx: Context, outcome: Outcome, source: str) -> Any:
    text = outcome.stdout if source == "stdout" else (ctx.folder / source).read_text(encoding="utf-8")
    return json.loads(text)


def _dig(obj: Any, key: str) -> Any:
    for part in key.split("."):
        obj = obj[int(part)] if isinstance(obj, list) else obj[part]
    return obj


def _check_json(ctx: Context, outcome: Outcome, source: str, key: str, op: str, value: Any) -> str | None:
    if outcome.code != 0:
        return None
    got = _dig(_json_source(ctx, outcome, source), key)
    import numpy as np

    def close() -> bool:
        a, b = np.asarray(got, float), np.asarray(value, float)
        return a.shape == b.shape and bool(np.allclose(a, b, rtol=1e-9, atol=1e-12))

    ok = {
        "==": lambda: got == value,
        "close": close,
        "<=": lambda: bool(np.all(np.asarray(got, float) <= np.asarray(value, float))),
        ">=": lambda: bool(np.all(np.asarray(got, float) >= np.asarray(value, float))),
    }[op]()
    return None if ok else f"{source} {key} = {got!r}, expected {op} {value!r}"


def _check_ik(
    ctx: Context, outcome: Outcome, robot: str | None, x: float, y: float, z: float | None
) -> str | None:
    if outcome.code != 0:
        return None
    import numpy as np

    from twolink_pin import load_robot
    from twolink_pin.kinematics import forward_kinematics, joint_positions

    where = robot if robot is None or not (ctx.folder / robot).exists() else str(ctx.folder / robot)
    model = load_robot(where)
    solutions = json.loads(outcome.stdout)["solutions"]
    if not solutions:
        return "ik answered no solution"
    target = np.array([x, y] if z is None else [x, y, z])
    misses = []
    for q in solutions:
        q_ = np.array(q, dtype=float)
        reached = forward_kinematics(model, q_) if z is None else joint_positions(model, q_)[-1]
        miss = float(np.linalg.norm(reached - target))
        if not miss <= 1e-9:
            misses.append(
                f"q = {np.round(q_, 6).tolist()} reaches {np.round(reached, 6).tolist()} ({miss:.3g} m off)"
            )
    return f"ik answer misses the target {tuple(target.tolist())}: {'; '.join(misses)}" if misses else None


def _check_fk(ctx: Context, outcome: Outcome, q1: float, q2: float) -> str | None:
    if outcome.code != 0:
        return None
    import numpy as np

    from twolink_pin.twolink.closed_form import forward_kinematics

    xy = json.loads(outcome.stdout)["xy"]
    expected = forward_kinematics(np.array([q1, q2]), 0.38, 0.24)
    if not np.allclose(xy, expected, atol=1e-12):
        return f"fk gives {xy}, the closed form {expected.tolist()}"
    return None


def _check_strict_json(ctx: Context, outcome: Outcome) -> str | None:
    if outcome.code != 0:
        return None

    def refuse(name: str) -> Any:
        raise ValueError(f"non-JSON constant {name}")

    try:
        json.loads(outcome.stdout, parse_constant=refuse)
    except ValueError as exc:
        return f"stdout is not strict JSON: {exc}"
    return None


def _check_secret(ctx: Context, outcome: Outcome, word: str) -> str | None:
    if word in outcome.stdout or word in outcome.stderr:
        return f"the content of a file that must never be read ({word!r}) appears in the output"
    return None


def _check_roundtrip(ctx: Context, outcome: Outcome, written: str, payload: float) -> str | None:
    if outcome.code != 0:
        return None
    import numpy as np

    from twolink_pin import load_robot
    from twolink_pin.dynamics import mass_matrix

    variant = load_robot(str(ctx.folder / written))
    expected = load_robot(payload=payload)
    if variant.nv != expected.nv:
        return f"{written} has nv = {variant.nv}, the twolink {expected.nv}"
    for q in ([0.0, 0.0], [0.3, -1.2], [2.0, 1.0]):
        q_ = np.array(q)
        got = mass_matrix(variant.model, variant.create_data(), q_)
        want = mass_matrix(expected.model, expected.create_data(), q_)
        if not np.allclose(got, want, rtol=1e-9, atol=1e-12):
            worst = float(np.max(np.abs(got - want) / np.maximum(np.abs(want), 1e-300)))
            return (
                f"{written} gives M({q}) = {got.tolist()}, --payload {payload} gives {want.tolist()} "
                f"(relative difference up to {worst:.2g}, more than 1e-9)"
            )
    return None


def _check_peak(ctx: Context, outcome: Outcome) -> str | None:
    if outcome.code != 0:
        return None
    data = json.loads(outcome.stdout)
    peak, limits = data["peak_torque"], data["torque_limits"]
    over = [(p, m) for p, m in zip(peak, limits) if m is not None and p > m + 1e-9]
    return f"--saturate: applied torque {peak} exceeds the limits {limits}" if over else None


def _check_symlink(ctx: Context, outcome: Outcome, path: str) -> str | None:
    return None if os.path.islink(ctx.folder / path) else f"{path} is no longer a symbolic link"


def _check_contains(ctx: Context, outcome: Outcome, path: str, word: str) -> str | None:
    if outcome.code != 0:
        return None
    text = (ctx.folder / path).read_text(encoding="utf-8", errors="replace")
    return None if word in text else f"{path} does not contain {word!r}"


def _check_finite_file(ctx: Context, outcome: Outcome, path: str) -> str | None:
    if outcome.code != 0:
        return None
    text = (ctx.folder / path).read_text(encoding="utf-8", errors="replace")
    hit = NONFINITE.search(text)
    return (
        f"{path} holds a non-finite value: {text[max(0, hit.start() - 30) : hit.end() + 10]!r}"
        if hit
        else None
    )


def _check_whole_or_absent(ctx: Context, outcome: Outcome, path: str, kind: str) -> str | None:
    target = ctx.folder / path
    if outcome.code == 0:
        if not target.exists():
            return f"exit 0 but {path} is missing"
        try:
            if kind == "npz":
                from twolink_pin.simulation.storage import load_result

                load_result(target)
            else:
                (target / "index.html").read_text(encoding="utf-8")
        except Exception as exc:
            return f"{path} is not whole after exit 0: {type(exc).__name__}: {exc}"
        return None
    if os.path.lexists(target) and kind == "npz":  # interrupted after it was committed: whole
        try:
            from twolink_pin.simulation.storage import load_result

            load_result(target)
        except Exception as exc:
            return f"{path} is partial after exit {outcome.code}: {type(exc).__name__}: {exc}"
    return None


CHECKS = {
    "whole_or_absent": _check_whole_or_absent,
    "json": _check_json,
    "ik_reaches": _check_ik,
    "fk_closed_form": _check_fk,
    "strict_json": _check_strict_json,
    "secret_kept": _check_secret,
    "urdf_roundtrip": _check_roundtrip,
    "peak_within_limits": _check_peak,
    "symlink": _check_symlink,
    "contains": _check_contains,
    "finite_file": _check_finite_file,
}


def cleanup(root: Path) -> None:
    """Remove a case's folders (modes restored first so that nothing blocks the removal)."""
    for top, dirs, _ in os.walk(root):
        for name in dirs:
            path = Path(top) / name
            if not path.is_symlink():  # a link may point out of the case folder (the repository)
                with contextlib.suppress(OSError):
                    os.chmod(path, 0o755)
    with contextlib.suppress(OSError):
        os.chmod(root, 0o755)
    shutil.rmtree(root, ignore_errors=True)
