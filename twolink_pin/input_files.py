"""Reading input files safely: a path is checked to be a bounded regular file before any read
(re-exported by :mod:`twolink_pin.files`, the writers' module, where callers find them).

Reading a FIFO, a device (``/dev/zero``) or a directory would block, never end, or fail
obscurely: they are refused before any read, as is a file larger than the reader's bound.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from twolink_pin.errors import InputFileError


def _reason(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def check_input_file(path: str | os.PathLike[str], max_bytes: int, what: str) -> Path:
    """``path`` if it is a regular file of at most ``max_bytes`` that this process can read.

    Reading a FIFO, a device (``/dev/zero``) or a directory would block, never end, or fail
    obscurely: they are refused before any read.

    Raises:
        InputFileError: missing, not a regular file, unreadable, or larger than ``max_bytes``
            (the message names the bound).
    """
    file = Path(path)
    try:
        info = os.stat(file)
    except FileNotFoundError:
        raise InputFileError(str(file), f"file not found (expected {what})") from None
    except OSError as exc:
        raise InputFileError(str(file), f"cannot be examined ({_reason(exc)})") from exc
    if stat.S_ISDIR(info.st_mode):
        raise InputFileError(str(file), f"is a directory (expected {what})")
    if not stat.S_ISREG(info.st_mode):
        raise InputFileError(str(file), f"is not a regular file (a device, pipe or socket; expected {what})")
    if info.st_size > max_bytes:
        raise InputFileError(
            str(file), f"is {info.st_size} bytes, more than the {max_bytes} bytes accepted for {what}"
        )
    if not os.access(file, os.R_OK):
        raise InputFileError(str(file), "cannot be read (permission denied)")
    return file


def read_input_file(path: str | os.PathLike[str], max_bytes: int, what: str) -> bytes:
    """The bytes of ``path`` after :func:`check_input_file`, read without following a swap to
    a device between the check and the read (the size is checked again on the open file)."""
    file = check_input_file(path, max_bytes, what)
    try:
        with open(file, "rb") as f:
            if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
                raise InputFileError(str(file), f"is not a regular file (expected {what})")
            data = f.read(max_bytes + 1)
    except OSError as exc:
        raise InputFileError(str(file), f"cannot be read ({_reason(exc)})") from exc
    if len(data) > max_bytes:
        raise InputFileError(str(file), f"is more than the {max_bytes} bytes accepted for {what}")
    return data


__all__ = ["check_input_file", "read_input_file"]
