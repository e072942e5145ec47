"""Where the page may write: a name typed into the page's "run file" or "animation file" box
is a file **inside the tuner's folder** (the working directory ``tune`` started in), never
an absolute path, a ``..`` that climbs out of it or a symbolic link that points out of it —
with ``--host 0.0.0.0`` whoever reaches the port types these names. What is written is also
offered as a download in the page (:meth:`Tuner._offer`)."""

from __future__ import annotations

import os
from pathlib import Path, PurePath

from twolink_pin.errors import InvalidParameterError

MAX_NAME = 255
"""Longest name accepted from the page [characters]."""


def page_path(folder: Path, text: str, suffix: str, what: str) -> Path:
    """The file the page's box ``what`` names: ``text`` relative to ``folder``, ending in
    ``suffix`` (``.npz``, ``.html``).

    Raises:
        InvalidParameterError: ``text`` is empty, too long, absolute, climbs out of
            ``folder`` (``..``, a symbolic link), or does not end in ``suffix``.
    """
    expected = f"a file name inside the tuner's folder {folder} ending in {suffix} (e.g. tune-run{suffix})"
    name = text.strip()
    if not name or len(name) > MAX_NAME or "\0" in name:
        raise InvalidParameterError(what, text, expected)
    pure = PurePath(name)
    if pure.is_absolute() or name.startswith("~") or os.path.splitdrive(name)[0]:
        raise InvalidParameterError(what, text, f"{expected}; an absolute path is refused")
    if ".." in pure.parts:
        raise InvalidParameterError(what, text, f"{expected}; '..' is refused")
    if pure.suffix.lower() != suffix:
        raise InvalidParameterError(what, text, expected)
    root = folder.resolve()
    target = (root / pure).resolve()  # a symbolic link on the way is followed, then checked
    if root not in target.parents:
        raise InvalidParameterError(what, text, f"{expected}; it leads to {target}, outside the folder")
    return target


__all__ = ["MAX_NAME", "page_path"]
