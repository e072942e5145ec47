"""Derivations kept on disk: an arm is derived once per kinematic content.

**Where**: ``$TWOLINK_PIN_CACHE`` if set (``off`` turns the cache off), else
``$XDG_CACHE_HOME/twolink-pin/equations``, else ``~/.cache/twolink-pin/equations``; one JSON
file per derivation, named by its key.

**Key and invalidation**: SHA-256 of the arm's :meth:`~twolink_pin.symbolic.skeleton.Skeleton.key`
(joint kinds, axes, placements' rotations, which offsets are nonzero, the gravity
direction), :data:`FORMAT` and the twolink-pin and SymPy versions. So an edited URDF whose
kinematics changed gets a new entry, one whose inertias, lengths' values or payload changed
reuses the old (those only give numbers, computed afresh each time), and a new release
derives again. Nothing is ever stale; old entries are only unused (``rm -r`` the folder to
reclaim the space: a 6-joint arm's entry is ~2 MB, a 3-joint arm's ~20 kB).

A missing, unreadable or malformed entry is derived again and rewritten; a folder that
cannot be written leaves the result uncached (no error: the equations stand).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from pathlib import Path

from twolink_pin.errors import OutputError
from twolink_pin.symbolic.derivation import Derivation, from_json, to_json

FORMAT = 1
"""Version of the stored form; raise it when :func:`~twolink_pin.symbolic.derivation.to_json` changes."""
ENVIRONMENT = "TWOLINK_PIN_CACHE"
"""The variable naming the cache folder (``off``: no cache)."""


def cache_folder() -> Path | None:
    """The folder derivations are kept in (module docstring); None when the cache is off."""
    chosen = os.environ.get(ENVIRONMENT)
    if chosen is not None:
        return None if chosen.strip().lower() in ("", "off", "0", "no") else Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "twolink-pin" / "equations"


def cache_key(skeleton_key: str) -> str:
    """The file name's key of a skeleton's derivation."""
    import sympy

    from twolink_pin.version import __version__

    text = f"{skeleton_key} format {FORMAT} twolink-pin {__version__} sympy {sympy.__version__}"
    return hashlib.sha256(text.encode()).hexdigest()


def cache_path(skeleton_key: str) -> Path | None:
    """Where the derivation of a skeleton is kept (None: the cache is off)."""
    folder = cache_folder()
    return None if folder is None else folder / f"{cache_key(skeleton_key)}.json"


def load(skeleton_key: str) -> Derivation | None:
    """The kept derivation of a skeleton, or None (none, off, or unreadable)."""
    path = cache_path(skeleton_key)
    if path is None or not path.is_file():
        return None
    try:
        return from_json(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def store(skeleton_key: str, derivation: Derivation) -> Path | None:
    """Keep ``derivation``; returns the file, or None if the cache is off or not writable."""
    from twolink_pin.files import atomic_write

    path = cache_path(skeleton_key)
    if path is None:
        return None
    with contextlib.suppress(OutputError, OSError):
        with atomic_write(path) as f:
            json.dump(to_json(derivation), f, separators=(",", ":"))
        return path
    return None
