"""What a corpus case is: :class:`Case`, its setup steps, its extra checks, and the file generators.

A case is data: the argv, what the folder holds before (setup steps, run in order in a fresh
temporary folder that is also the working directory), the expected exit status, the words
stderr must contain, the files that must exist or be absent afterwards, and how to run it
(in this process, or as a real process: plain, without the capabilities that let root ignore
permissions, on a full disk, with a private ``/dev``, with stdout closed or full, or
interrupted by a signal). The invariants every case must meet are in ``runner.py``.
"""

from __future__ import annotations

import io
import json
import signal
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

CORPUS = Path(__file__).resolve().parent
"""This folder: ``urdf/`` (hand-written robots) and ``laws/`` (control laws written as a user would)."""
URDF = CORPUS / "urdf"
LAWS = CORPUS / "laws"

CLASSES = {
    "dataloss": "1. data loss: a user's folder or file overwritten, a device replaced, a partial file",
    "wrong": "2. wrong answers accepted: a value silently changed or an option ignored",
    "hang": "3. hangs and unbounded work: blocking reads, endless input, absurd sizes",
    "traceback": "4. tracebacks instead of one-line errors: read-only, full disk, closed stdout, bad files",
    "nonfinite": "5. silent inf/NaN: huge and non-finite numbers",
    "unclear": "6. unclear messages: what works must work, what fails must say why",
    "interrupt": "7. interrupts: SIGINT and SIGTERM on running commands",
    "library": "6b. library-level arguments: wrong sizes, NaN, wrong types",
    "usercode": "8. user code contained: laws and plug-ins that exit, print, write their inputs, exhaust memory, never return",
}
"""Case classes, by the first word of a case id."""

RUNNERS = (
    "inproc",  # twolink_pin.cli.main(argv) in this process, stdout/stderr captured at the fd level
    "proc",  # python -m twolink_pin.cli as a real process
    "setpriv",  # the same without CAP_DAC_OVERRIDE / CAP_DAC_READ_SEARCH / CAP_FOWNER (root obeys modes)
    "fullfs",  # in a private mount namespace where ./full is a 32 KiB tmpfs
    "fullfs-filled",  # the same, the tmpfs filled to the last byte first (./full/filler)
    "devsandbox",  # in a private mount namespace with a private /dev (null, zero, full, ...)
    "stdout-closed",  # sh -c '... >&-'
    "stdout-full",  # stdout is /dev/full
    "stderr-closed",  # sh -c '... 2>&-'
    "stdin-pipe",  # stdin is a pipe nobody writes to or closes
    "signal",  # a real process that gets Case.signal when it reports a stage
)


class Step(NamedTuple):
    """One setup step (see the helper functions below)."""

    kind: str
    path: str
    arg: Any = None


class Check(NamedTuple):
    """One extra check after the run (implemented in ``runner.py``)."""

    kind: str
    args: tuple[Any, ...] = ()


@dataclass(frozen=True)
class Case:
    """One hostile input and its expected outcome.

    Attributes:
        id: ``class-command-what``; the class is the first word (see :data:`CLASSES`).
        argv: The arguments after ``twolink-pin``; ``{corpus}``, ``{dir}`` (the case folder)
            and ``{port}`` (a port held busy by the harness) are substituted.
        exit: The expected exit status, or the statuses accepted.
        err: Words stderr must contain when the exit is not 0, case-insensitive; ``"a|b"``
            accepts either.
        out: Words stdout must contain when the exit is 0.
        not_err: Words stderr must not contain.
        setup: Steps run in order in the empty case folder.
        exists: Paths that must exist afterwards.
        absent: Paths that must not exist afterwards.
        changed: Pre-existing paths (or folders) that may change; every other file present
            after the setup must be byte-identical afterwards.
        chardev: Paths that must still be character devices afterwards.
        checks: Extra checks.
        run: How to run it (:data:`RUNNERS`).
        signal: ``(signum, stage, "group" | "parent")`` for the ``signal`` runner: the signal
            goes out as soon as the program reports ``stage`` (``started``, ``parsed``,
            ``running``, ``writing``, ``serving``: :mod:`twolink_pin.readiness`), never after a delay.
        nonfinite_ok: A successful run may print ``nan`` / ``inf``.
        warns: Words a successful run's stderr must hold (a warning, a law's own prints); a
            success may then print on stderr.
        silent_ok: A failed run may print nothing on stderr (stdout unwritable, killed).
        timeout: Seconds before the case counts as a hang (the default is generous: every case
            that works takes a few seconds at most).
        env: Extra environment of a real process.
        memory: Address-space limit of a real process [bytes] (reading an endless input
            fails fast instead of exhausting the machine).
        cwd: Working directory below the case folder.
        note: Why the expectation is what it is, where that is a judgement.
    """

    id: str
    argv: tuple[str, ...]
    exit: int | tuple[int, ...]
    err: tuple[str, ...] = ()
    out: tuple[str, ...] = ()
    not_err: tuple[str, ...] = ()
    setup: tuple[Step, ...] = ()
    exists: tuple[str, ...] = ()
    absent: tuple[str, ...] = ()
    changed: tuple[str, ...] = ()
    chardev: tuple[str, ...] = ()
    checks: tuple[Check, ...] = ()
    run: str = "inproc"
    signal: tuple[int, str, str] | None = None
    nonfinite_ok: bool = False
    warns: tuple[str, ...] = ()
    silent_ok: bool = False
    timeout: float = 20.0
    env: tuple[tuple[str, str], ...] = ()
    memory: int | None = None
    cwd: str = "."
    note: str = ""

    def __post_init__(self) -> None:
        if self.cls not in CLASSES:
            raise ValueError(f"case {self.id!r}: unknown class {self.cls!r}; expected one of {list(CLASSES)}")
        if self.run not in RUNNERS:
            raise ValueError(f"case {self.id!r}: unknown runner {self.run!r}")
        if (self.run == "signal") != (self.signal is not None):
            raise ValueError(f"case {self.id!r}: the signal runner and Case.signal go together")
        if self.signal is not None and self.signal[1] not in STAGES:
            raise ValueError(f"case {self.id!r}: stage {self.signal[1]!r} is not one of {STAGES}")

    @property
    def cls(self) -> str:
        """The case's class: the first word of its id."""
        return self.id.split("-", 1)[0]

    @property
    def exits(self) -> tuple[int, ...]:
        """The accepted exit statuses."""
        return (self.exit,) if isinstance(self.exit, int) else tuple(self.exit)


@dataclass(frozen=True)
class LibCase:
    """A call into the library that must raise ``exc`` with every word of ``words`` in its message.

    ``expr`` is evaluated with ``np``, ``tp`` (twolink_pin), ``dynamics``, ``kinematics``,
    ``robot`` (the twolink), ``model``, ``data``, ``plant``, ``trajectory``, ``controller``
    (pd on the twolink), ``SimulationConfig`` and ``Path`` in scope.
    """

    id: str
    expr: str
    words: tuple[str, ...]
    exc: str = "InvalidParameterError"
    note: str = ""

    @property
    def cls(self) -> str:
        return "library"


# -- extra checks (implemented in runner.CHECKS) ---------------------------------------------


def json_at(source: str, key: str, op: str, value: Any) -> Check:
    """``source`` (``"stdout"`` or a JSON file) at ``key`` (dotted, list indices as numbers)
    compares ``op`` (``==``, ``close``, ``<=``, ``>=``) to ``value`` (after a success)."""
    return Check("json", (source, key, op, value))


def ik_reaches(robot: str | None, x: float, y: float, z: float | None = None) -> Check:
    """Every ``ik --json`` answer reaches ``(x, y)`` (or ``(x, y, z)``) within 1e-9 m by the
    library's FK; ``robot`` is a URDF in the case folder, a catalog name, or None (twolink)."""
    return Check("ik_reaches", (robot, x, y, z))


def fk_closed_form(q1: float, q2: float) -> Check:
    """``fk --json`` on the twolink equals the closed form (L1 = 0.38, L2 = 0.24 m)."""
    return Check("fk_closed_form", (q1, q2))


def strict_json() -> Check:
    """stdout parses as JSON without NaN / Infinity constants."""
    return Check("strict_json")


def secret_kept(word: str) -> Check:
    """``word`` (the content of a file that must never be read) appears neither on stdout nor stderr."""
    return Check("secret_kept", (word,))


def urdf_roundtrip(written: str, payload: float) -> Check:
    """The URDF ``written`` by ``--write-urdf`` has the same mass matrix M(q) as the twolink with ``payload``."""
    return Check("urdf_roundtrip", (written, payload))


def peak_within_limits() -> Check:
    """``simulate --json``: the applied peak torque is within the effort limits."""
    return Check("peak_within_limits")


def still_symlink(path: str) -> Check:
    """``path`` is still a symbolic link."""
    return Check("symlink", (path,))


def contains(path: str, word: str) -> Check:
    """The file ``path`` contains ``word`` (after a success)."""
    return Check("contains", (path, word))


def finite_file(path: str) -> Check:
    """The text file ``path`` holds no nan / inf (after a success)."""
    return Check("finite_file", (path,))


def whole_or_absent(path: str, kind: str = "npz") -> Check:
    """After an interrupt that may have come too late to stop the command: ``path`` is absent
    or a whole file that loads (the signal came after it was committed; exit 0 requires it);
    never a partial file."""
    return Check("whole_or_absent", (path, kind))


# -- setup steps -------------------------------------------------------------------------------


def text(path: str, content: str) -> Step:
    """A text file (UTF-8)."""
    return Step("text", path, content)


def blob(path: str, content: bytes | Callable[[Path], bytes]) -> Step:
    """A file of bytes, or of what ``content(case_folder)`` returns."""
    return Step("blob", path, content)


def urdf(name: str, as_: str | None = None) -> Step:
    """A copy of ``urdf/<name>.urdf`` as ``as_`` (default ``<name>.urdf``)."""
    return Step("copy", as_ or f"{name}.urdf", URDF / f"{name}.urdf")


def twolink(as_: str, *subs: tuple[str, str]) -> Step:
    """A copy of the shipped ``twolink.urdf`` with each ``(old, new)`` replaced once (old must occur)."""
    return Step("twolink", as_, subs)


def folder(path: str) -> Step:
    """A folder (and its parents)."""
    return Step("folder", path)


def fifo(path: str) -> Step:
    """A named pipe."""
    return Step("fifo", path)


def device(path: str, kind: str) -> Step:
    """A character device node like ``/dev/<kind>`` (null, zero, full) in the case folder."""
    return Step("device", path, kind)


def unix_socket(path: str) -> Step:
    """A Unix socket bound at ``path`` (and left bound while the case runs)."""
    return Step("socket", path)


def cli(*argv: str) -> Step:
    """A preceding ``twolink-pin`` run in the case folder that must succeed (e.g. a first report)."""
    return Step("cli", "", tuple(argv))


def chmod(path: str, mode: int) -> Step:
    """Change a mode (put it after the steps that fill the folder)."""
    return Step("chmod", path, mode)


def symlink(path: str, target: str) -> Step:
    """A symbolic link ``path`` → ``target``."""
    return Step("symlink", path, target)


def truncate(path: str, size: int) -> Step:
    """Cut a file to its first ``size`` bytes."""
    return Step("truncate", path, size)


# -- generated files ---------------------------------------------------------------------------


def _twolink_text() -> str:
    import twolink_pin

    return twolink_pin.twolink_urdf_path().read_text(encoding="utf-8")


def urdf_bound() -> int:
    """The URDF size bound of the loader if it has one, else 32 MiB (what a demanding user expects)."""
    from twolink_pin.model import urdf_validation

    return int(getattr(urdf_validation, "MAX_URDF_BYTES", 32 * 2**20))


def utf16(with_declaration: bool) -> Callable[[Path], bytes]:
    """The twolink encoded as UTF-16 (with a BOM), its declaration saying so or absent."""

    def make(_: Path) -> bytes:
        body = _twolink_text()
        if with_declaration:
            body = body.replace('<?xml version="1.0"?>', '<?xml version="1.0" encoding="UTF-16"?>', 1)
        else:
            body = body.replace('<?xml version="1.0"?>\n', "", 1)
        return body.encode("utf-16")

    return make


def utf8_bom(_: Path) -> bytes:
    """The twolink with a UTF-8 byte-order mark: valid XML, must load."""
    return b"\xef\xbb\xbf" + _twolink_text().encode("utf-8")


def crlf(_: Path) -> bytes:
    """The twolink with Windows line ends: valid XML, must load."""
    return _twolink_text().replace("\n", "\r\n").encode("utf-8")


def oversize(_: Path) -> bytes:
    """The twolink padded with comments to 1 MiB over the URDF size bound."""
    pad = b"<!-- " + b"x" * (2**16 - 9) + b" -->\n"
    count = (urdf_bound() + 2**20) // len(pad) + 1
    head, _, tail = _twolink_text().encode("utf-8").partition(b"<robot")
    return head + pad * count + b"<robot" + tail


def deep_nesting(_: Path) -> bytes:
    """The twolink with 100 000 nested <gazebo> elements inside <robot> (a stack-depth bomb)."""
    depth = 100_000
    nest = "<gazebo>" * depth + "</gazebo>" * depth
    return _twolink_text().replace('<robot name="twolink">', '<robot name="twolink">' + nest, 1).encode()


def many_links(_: Path) -> bytes:
    """A chain of one link more than the loader's cap (MAX_LINKS, 1000 if absent)."""
    from twolink_pin.model import urdf_validation

    n = int(getattr(urdf_validation, "MAX_LINKS", 1000)) + 1
    inertial = (
        '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
        "</inertial>"
    )
    parts = ['<?xml version="1.0"?>\n<robot name="chain">', f'<link name="l0">{inertial}</link>']
    for i in range(1, n):
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="0.01 0 0"/><axis xyz="0 0 1"/>'
            f'<limit lower="-1" upper="1" effort="1" velocity="1"/></joint><link name="l{i}">{inertial}</link>'
        )
    parts.append("</robot>\n")
    return "\n".join(parts).encode()


def garbage(size: int) -> Callable[[Path], bytes]:
    """``size`` pseudo-random bytes (fixed seed)."""
    return lambda _: np.random.default_rng(1234).bytes(size)


def _npz(**arrays: Any) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


def npz_from_saved(source: str, **changes: Any) -> Callable[[Path], bytes]:
    """``source`` (a saved result in the case folder) with arrays replaced (``None`` drops one);
    a callable change gets the old array."""

    def make(folder_: Path) -> bytes:
        with np.load(folder_ / source, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        for key, value in changes.items():
            if value is None:
                arrays.pop(key, None)
            else:
                arrays[key] = value(arrays[key]) if callable(value) else value
        return _npz(**arrays)

    return make


def npz_arrays(**arrays: Any) -> Callable[[Path], bytes]:
    """An ``.npz`` of the given arrays."""
    return lambda _: _npz(**arrays)


def npz_pickled(_: Path) -> bytes:
    """An ``.npz`` whose ``q`` is an object array (loading it needs pickle, which is refused)."""
    return _npz(controller=np.array("pd"), t=np.arange(3.0), q=np.array([{"a": 1}], dtype=object))


def npz_huge_header(_: Path) -> bytes:
    """An ``.npz`` whose ``q.npy`` header claims shape (10**6, 10**6) float64 (8 TB) over 16 bytes of data."""
    header = "{'descr': '<f8', 'fortran_order': False, 'shape': (1000000, 1000000), }"
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    npy = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode() + b"\x00" * 16
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as z:
        z.writestr("controller.npy", _npy(np.array("pd")))
        z.writestr("t.npy", _npy(np.arange(3.0)))
        z.writestr("q.npy", npy)
    return buffer.getvalue()


def npz_bomb(_: Path) -> bytes:
    """An ``.npz`` of 4 MB whose ``q.npy`` inflates to 4 GiB of zeros (a zip bomb)."""
    chunk = b"\x00" * 2**24
    chunks = 4 * 2**30 // len(chunk)
    n = chunks * len(chunk) // 16
    header = f"{{'descr': '<f8', 'fortran_order': False, 'shape': ({n}, 2), }}"
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    head = b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header.encode()
    # After a full flush the compressor forgets its history, so every chunk deflates to the same bytes.
    compressor = zlib.compressobj(9, zlib.DEFLATED, -15)
    first = compressor.compress(head) + compressor.flush(zlib.Z_FULL_FLUSH)
    block = compressor.compress(chunk) + compressor.flush(zlib.Z_FULL_FLUSH)
    deflated = first + block * chunks + compressor.flush()
    crc = zlib.crc32(head)
    for _ in range(chunks):
        crc = zlib.crc32(chunk, crc)
    controller = _npy(np.array("pd"))
    return _zip(
        [
            ("controller.npy", 0, zlib.crc32(controller), controller, len(controller)),
            ("q.npy", 8, crc, deflated, len(head) + chunks * len(chunk)),
        ]
    )


def _npy(array: np.ndarray) -> bytes:
    buffer = io.BytesIO()
    np.save(buffer, array)
    return buffer.getvalue()


def _zip(members: list[tuple[str, int, int, bytes, int]]) -> bytes:
    """A zip file of ``(name, method, crc, stored bytes, uncompressed size)`` members, ZIP64 sizes
    where they do not fit 32 bits."""
    import struct

    out = io.BytesIO()
    central = []
    for name, method, crc, stored, size in members:
        offset = out.tell()
        raw = name.encode()
        big = size >= 0xFFFFFFFF or len(stored) >= 0xFFFFFFFF
        extra = struct.pack("<HHQQ", 1, 16, size, len(stored)) if big else b""
        sizes = (0xFFFFFFFF, 0xFFFFFFFF) if big else (len(stored), size)
        out.write(
            struct.pack("<IHHHHHIIIHH", 0x04034B50, 45, 0, method, 0, 0, crc, *sizes, len(raw), len(extra))
        )
        out.write(raw + extra + stored)
        central.append(
            struct.pack(
                "<IHHHHHHIIIHHHHHII",
                0x02014B50,
                45,
                45,
                0,
                method,
                0,
                0,
                crc,
                *sizes,
                len(raw),
                len(extra),
                0,
                0,
                0,
                0,
                offset,
            )
            + raw
            + extra
        )
    start = out.tell()
    for entry in central:
        out.write(entry)
    size = out.tell() - start
    out.write(struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(central), len(central), size, start, 0))
    return out.getvalue()


def json_file(obj: Any) -> str:
    """``obj`` as JSON text."""
    return json.dumps(obj)


SIGINT, SIGTERM = int(signal.SIGINT), int(signal.SIGTERM)
STAGES = ("started", "parsed", "running", "writing", "serving")
"""The stages the program reports (:mod:`twolink_pin.readiness`), in order."""
