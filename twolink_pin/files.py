"""Writing files safely: the one writer every output goes through.

* :func:`atomic_write` — a file: the content goes to a temporary file in the target's
  directory, flushed to disk, which then replaces the target in one ``os.replace``. An
  error midway never leaves a half-written file; an existing target is replaced only if it
  is a regular file (never a device, a pipe or a directory).
* :func:`output_directory` — a folder of outputs: built in a staging folder beside it and
  moved into place only when complete. An existing folder is replaced only if it is empty
  or was written by the same command (its marker file), so a user's folder is never
  overwritten.
* :func:`write_json` — JSON through :func:`atomic_write` (no NaN or inf: they are not JSON).
* :func:`outputs_together` — one command's files, all or nothing: inside it
  :func:`atomic_write` stages each file beside its target and :func:`commit_outputs` (the CLI
  calls it before it prints its summary) moves them all into place, or none when the command
  fails; a folder of figures (:func:`removed_on_failure`, ``--plot DIR``) is the command's only
  for the names its marker (:data:`FIGURES_MARKER`) lists: a file of yours of the same name as a
  figure is never replaced.

Every OS failure (read-only folder, full disk, a file where a folder is expected) becomes
an :class:`~twolink_pin.errors.OutputError` naming the path and the reason.
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import json
import os
import shutil
import signal
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

from twolink_pin.errors import OutputError

# the readers' checks, re-exported beside the writer
from twolink_pin.input_files import check_input_file as check_input_file
from twolink_pin.input_files import read_input_file as read_input_file
from twolink_pin.readiness import ready
from twolink_pin.user_code import restore_baseline


def _reason(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


class OutputSet:
    """The files one command writes, staged beside their targets and moved into place together
    (:func:`outputs_together`)."""

    def __init__(self) -> None:
        self.staged: list[tuple[Path, Path]] = []
        """``(temporary file, target)`` in the order written (a later write of a target wins)."""
        self.created: list[Path] = []
        """Folders made for the staged files, deepest first (removed again if the set is discarded)."""
        self.claimed: set[Path] = set()
        """Folders of figures (their real paths): a file there is replaced only if their
        :data:`FIGURES_MARKER` lists it."""

    def _check(self) -> None:
        for _, target in self.staged:
            check_replaceable(target)  # nothing else took the name meanwhile
            folder = target.parent
            if folder in self.claimed and target.exists() and target.name not in _listed(folder):
                raise OutputError(
                    str(target),
                    f"is not a figure twolink-pin wrote (the folder's {FIGURES_MARKER} does not list it); refusing "
                    "to replace it with one — move it, or give another folder",
                )

    def commit(self) -> None:
        """Move every staged file into place (signals held for the renames); the figure
        folders' markers list what they now hold of ours.

        Raises:
            OutputError: a target became a folder or a device, or is a file of the user's in a
                folder of figures: nothing is moved then.
        """
        try:
            self._check()
            for folder in sorted(self.claimed):
                names = {t.name for _, t in self.staged if t.parent == folder}
                if names:
                    _write_listing(folder, _listed(folder) | names)
            with _signals_deferred():
                for tmp, target in self.staged:
                    os.replace(tmp, target)
                    _STAGING.discard(str(tmp))
        except OSError as exc:
            self.discard()
            raise OutputError(str(self.staged[0][1]), f"cannot write the file ({_reason(exc)})") from exc
        except BaseException:
            self.discard()
            raise
        self.staged.clear()
        self.created.clear()

    def discard(self) -> None:
        """Remove every staged file and the folders made for them (when empty)."""
        for tmp, _ in self.staged:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            _STAGING.discard(str(tmp))
        for folder in self.created:
            with contextlib.suppress(OSError):
                folder.rmdir()
        self.staged.clear()
        self.created.clear()


_PENDING: contextvars.ContextVar[OutputSet | None] = contextvars.ContextVar(
    "twolink_pin_outputs", default=None
)

_STAGING: set[str] = set()
"""Temporary files and staging folders that exist now (what :func:`remove_staging` removes)."""


def remove_staging() -> None:
    """Remove every temporary file and staging folder this process has made and not yet moved
    into place or removed: for an exit that runs no ``finally`` (the deadline's backstop,
    :mod:`twolink_pin.simulation.deadline`)."""
    for path in sorted(_STAGING, reverse=True):
        if os.path.isdir(path) and not os.path.islink(path):
            shutil.rmtree(path, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                os.unlink(path)
    _STAGING.clear()


FIGURES_MARKER = ".twolink-pin-figures"
"""The file in a ``--plot`` folder that lists the figures twolink-pin wrote there (``entry:
NAME`` lines): only those are replaced by the next command's figures."""


@contextlib.contextmanager
def outputs_together() -> Iterator[OutputSet]:
    """The files written inside the block (through :func:`atomic_write`) are staged and moved
    into place together when the block ends without an exception (or earlier, at
    :func:`commit_outputs`); on an exception none is, and nothing staged stays behind. A
    folder written as a whole (:func:`output_directory`) is its own unit: its files are not
    staged twice."""
    pending = OutputSet()
    token = _PENDING.set(pending)
    try:
        yield pending
        pending.commit()
    except BaseException:
        pending.discard()
        raise
    finally:
        _PENDING.reset(token)


def commit_outputs() -> None:
    """Move the files staged so far (:func:`outputs_together`) into place; nothing outside it."""
    pending = _PENDING.get()
    if pending is not None:
        pending.commit()


def _listed(folder: Path) -> set[str]:
    try:
        text = (folder / FIGURES_MARKER).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return set()
    return {line[len(MANIFEST_PREFIX) :] for line in text.splitlines() if line.startswith(MANIFEST_PREFIX)}


def _write_listing(folder: Path, names: set[str]) -> None:
    token = _PENDING.set(None)  # written now: it must list a figure before the figure is there
    try:
        with atomic_write(folder / FIGURES_MARKER) as f:
            f.write("figures written by twolink-pin (--plot); a file not listed here is never replaced\n")
            f.write("".join(f"{MANIFEST_PREFIX}{name}\n" for name in sorted(names)))
    finally:
        _PENDING.reset(token)


def _missing_folders(path: Path) -> list[Path]:
    """The folders of ``path`` (itself included) that do not exist, deepest first."""
    missing = []
    probe = path
    while not probe.exists() and probe != probe.parent:
        missing.append(probe)
        probe = probe.parent
    return missing


def _make_parent(target: Path) -> None:
    parent = target.parent
    pending = _PENDING.get()
    if pending is not None:
        pending.created.extend(_missing_folders(parent))
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise OutputError(str(parent), "exists and is not a directory") from None
    except OSError as exc:
        raise OutputError(str(parent), f"cannot create the directory ({_reason(exc)})") from exc
    if not parent.is_dir():
        raise OutputError(str(parent), "exists and is not a directory")


def check_replaceable(path: str | os.PathLike[str]) -> Path:
    """``path`` (symbolic links followed) if a file may be written there: absent or a
    regular file. Raises :class:`OutputError` for a directory, a device, a pipe, a socket."""
    target = Path(path)
    try:
        info = os.stat(target)
    except FileNotFoundError:
        return target
    except NotADirectoryError:
        parent = next((p for p in target.parents if p.exists()), None)
        raise OutputError(str(parent or target), "exists and is not a directory") from None
    except OSError as exc:
        raise OutputError(str(target), f"cannot be examined ({_reason(exc)})") from exc
    if stat.S_ISDIR(info.st_mode):
        raise OutputError(str(target), "is a directory; expected a file path")
    if not stat.S_ISREG(info.st_mode):
        raise OutputError(
            str(target), "is not a regular file (a device, pipe or socket); refusing to replace it"
        )
    return Path(os.path.realpath(target))


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO[Any]]:
    """Open a temporary file beside ``path``; on success flush it and move it onto ``path``.

    Raises:
        OutputError: ``path`` is a directory or not a regular file, or the folder cannot be
            created or written (read-only, full, a file in the way).
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
    restore_baseline()  # a law that changed the working directory cannot move the output
    target = check_replaceable(path)
    _make_parent(target)
    try:
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
    except OSError as exc:
        raise OutputError(str(target), f"cannot write in {target.parent} ({_reason(exc)})") from exc
    _STAGING.add(tmp)
    try:
        try:
            with os.fdopen(fd, mode, encoding=None if "b" in mode else "utf-8") as f:
                ready("writing")
                yield f
                f.flush()
                os.fsync(f.fileno())
            os.chmod(tmp, 0o666 & ~_umask())
            check_replaceable(target)  # nothing else took the name meanwhile
            pending = _PENDING.get()
            if pending is not None:  # moved into place with the command's other outputs
                pending.staged.append((Path(tmp), Path(os.path.realpath(target))))
            else:
                os.replace(tmp, target)
                _STAGING.discard(tmp)
        except OSError as exc:
            raise OutputError(str(target), f"cannot write the file ({_reason(exc)})") from exc
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        _STAGING.discard(tmp)
        raise


@contextlib.contextmanager
def removed_on_failure(folder: str | os.PathLike[str]) -> Iterator[Path]:
    """A block that may create ``folder`` (and its missing parents) for files whose names the
    command chooses (``--plot DIR``'s figures): if the block fails, the folders it created are
    removed again when they are still empty (a full disk or a read-only file then leaves
    nothing behind). Inside :func:`outputs_together` the folder is claimed: a file of the same
    name as one written there is replaced only if the folder's :data:`FIGURES_MARKER` lists it."""
    path = Path(folder)
    missing = _missing_folders(path)
    pending = _PENDING.get()
    if pending is not None:
        pending.claimed.add(Path(os.path.realpath(path)))
    try:
        yield path
    except BaseException:
        for created in missing:  # deepest first
            with contextlib.suppress(OSError):
                created.rmdir()
        raise


def write_json(path: str | os.PathLike[str], obj: Any) -> Path:
    """Write ``obj`` as indented JSON, atomically."""
    text = json.dumps(obj, indent=2, allow_nan=False)
    with atomic_write(path) as f:
        f.write(text)
        f.write("\n")
    return Path(path)


MANIFEST_PREFIX = "entry: "
"""Lines of a marker file that name an entry the command wrote into its folder."""


def _is_ours(folder: Path, marker: str) -> bool:
    try:
        entries = sorted(p.name for p in folder.iterdir())
    except OSError as exc:
        raise OutputError(str(folder), f"cannot be listed ({_reason(exc)})") from exc
    if not entries:
        return True
    if marker not in entries or not (folder / marker).is_file():
        return False
    try:
        text = (folder / marker).read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise OutputError(str(folder / marker), f"cannot be read ({_reason(exc)})") from exc
    listed = {line[len(MANIFEST_PREFIX) :] for line in text.splitlines() if line.startswith(MANIFEST_PREFIX)}
    if not listed:
        return True  # a marker from before manifests: the whole folder is ours
    foreign = [name for name in entries if name != marker and name not in listed]
    if foreign:
        raise OutputError(
            str(folder),
            f"holds {foreign[0]!r}, which this command did not write; refusing to replace the folder (and lose "
            "it) — move it out, or give a new or empty directory",
        )
    return True


def _is_mount_point(folder: Path) -> bool:
    """Whether ``folder`` is a mount point (bind mounts too, from /proc/self/mountinfo on
    Linux): a folder that cannot be renamed, found before the work rather than after it."""
    if os.path.ismount(folder):
        return True
    try:
        resolved = str(folder.resolve())
        with open("/proc/self/mountinfo", encoding="utf-8", errors="replace") as f:
            points = {
                line.split()[4].encode().decode("unicode_escape") for line in f if len(line.split()) > 4
            }
    except OSError:
        return False
    return resolved in points


def check_output_directory(path: str | os.PathLike[str], marker: str) -> Path:
    """``path`` if an output folder may be written there: absent, empty, or one the same
    command wrote (holding ``marker``, which lists what it wrote: a folder that also holds
    anything else is refused). Raises :class:`OutputError` otherwise."""
    out = Path(path)
    if not str(path):
        raise OutputError("''", "is an empty path; expected a folder name")
    if out.is_symlink():  # the swap would replace the link, not the folder it points to
        raise OutputError(
            str(out),
            f"is a symbolic link (to {os.readlink(out)!r}); an output folder is replaced as a whole, which "
            "would replace the link: give the folder's own path or a new name",
        )
    if out.exists() and not out.is_dir():
        raise OutputError(str(out), "exists and is not a directory")
    if out.exists() and not os.access(out, os.W_OK | os.X_OK):
        raise OutputError(
            str(out), "is not writable (its permissions); refusing to replace it with a writable folder"
        )
    if out.exists() and _is_mount_point(out):
        raise OutputError(
            str(out),
            "is a mount point: the finished folder could not replace it (it is swapped in whole); give a "
            "folder inside it",
        )
    if out.exists() and not _is_ours(out, marker):
        raise OutputError(
            str(out),
            f"is a non-empty directory this command did not write ({marker} missing); refusing to overwrite it "
            "— give a new or empty directory",
        )
    return out


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """SIGINT and SIGTERM held back (delivered when the block ends): for the few system
    calls that must happen together or not at all."""
    held = {signal.SIGINT, signal.SIGTERM}
    try:
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    except (AttributeError, OSError, ValueError):  # no POSIX signal masks here
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


@contextlib.contextmanager
def output_directory(path: str | os.PathLike[str], marker: str, note: str = "") -> Iterator[Path]:
    """A staging folder that replaces ``path`` when the block succeeds.

    The folder ``path`` must be absent, empty, or one this command wrote (holding
    ``marker``). The block writes into the yielded staging folder (beside ``path``, hidden);
    on success ``marker`` is written into it and it is swapped into place (the old folder
    removed); on failure or interruption it is removed and ``path`` is left as it was.

    Raises:
        OutputError: ``path`` is someone else's folder, a file, or its parent cannot be
            written.
    """
    restore_baseline()  # a law that changed the working directory cannot move the output
    out = check_output_directory(path, marker)
    _make_parent(out)
    token = _PENDING.set(None)  # the folder is the unit: its files are written in its stage now
    try:
        with _output_stage(out, marker, note) as stage:
            yield stage
    finally:
        _PENDING.reset(token)


@contextlib.contextmanager
def _output_stage(out: Path, marker: str, note: str) -> Iterator[Path]:
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-", dir=out.parent))
    except OSError as exc:
        raise OutputError(str(out.parent), f"cannot create a folder there ({_reason(exc)})") from exc
    _STAGING.add(str(stage))
    try:
        os.chmod(stage, 0o777 & ~_umask())
        ready("writing")
        yield stage
        written = sorted(p.name for p in stage.iterdir() if p.name != marker)
        manifest = "".join(f"{MANIFEST_PREFIX}{name}\n" for name in written)
        (stage / marker).write_text(
            (note or f"written by twolink-pin ({marker})\n") + manifest, encoding="utf-8"
        )
        check_output_directory(out, marker)  # still ours after the work
        old = None
        with _signals_deferred():  # Ctrl-C between the two renames would lose the old folder
            if out.exists():
                old = out.parent / f".{out.name}.old-{os.getpid()}"
                os.replace(out, old)
            os.replace(stage, out)
            _STAGING.discard(str(stage))
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except OSError as exc:
        shutil.rmtree(stage, ignore_errors=True)
        _STAGING.discard(str(stage))
        code = errno.errorcode.get(exc.errno or 0, "")
        raise OutputError(
            str(out), f"cannot write the outputs ({_reason(exc)}{', ' + code if code else ''})"
        ) from exc
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        _STAGING.discard(str(stage))
        raise
