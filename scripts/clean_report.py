"""Remove what ``twolink-pin report`` wrote into a folder, and nothing else (``make clean``).

    python3 scripts/clean_report.py out

The report folder holds a marker (``.twolink-pin-report``) that lists every entry the report
wrote (``entry: NAME`` lines; a marker without them, from before the lists, claims the whole
folder). Those entries and the marker are removed, then the folder if it is empty. A folder
without the marker is not the report's and is left alone; an entry the marker does not list
(a file of yours put there later) stays and is named. Standard library only: it runs with
the system's Python after the virtual environment is gone.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

MARKER = ".twolink-pin-report"
"""The report folder's marker (``twolink_pin.report.MARKER``; a test checks they agree)."""
ENTRY = "entry: "
"""A marker line naming an entry (``twolink_pin.files.MANIFEST_PREFIX``)."""


def clean(folder: Path) -> list[str]:
    """Remove the report's entries from ``folder`` (module doc); the names left behind."""
    marker = folder / MARKER
    if folder.is_symlink() or not folder.is_dir() or marker.is_symlink() or not marker.is_file():
        return []
    lines = marker.read_text(encoding="utf-8", errors="replace").splitlines()
    listed = {line[len(ENTRY) :] for line in lines if line.startswith(ENTRY)}
    whole = not listed
    for entry in sorted(folder.iterdir()):
        if entry.name == MARKER or not (whole or entry.name in listed):
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()
    marker.unlink()
    left = sorted(p.name for p in folder.iterdir())
    if not left:
        folder.rmdir()
    return left


def main(argv: list[str]) -> int:
    for name in argv:
        left = clean(Path(name))
        if left:
            print(
                f"clean_report: kept {name}/ ({', '.join(left)}: not written by the report)", file=sys.stderr
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
