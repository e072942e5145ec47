"""``twolink-pin examples``: the example files the documentation's commands use, shipped with the
package (``twolink_pin.examples``), listed or copied into a folder of yours.

From a ``pip install`` there is no clone to hold ``examples/``; ``twolink-pin examples --copy
examples`` writes them there, and the pages' commands (``--trajectory
examples/ur5_square_pose.toml``, ``examples/sliding_mode.py:SlidingMode``) run from the folder
that holds it. A file of the folder that differs from the shipped one is yours: the copy is
refused naming it (nothing is written); an identical one is left as it is.
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path
from typing import Any

from twolink_pin.errors import OutputError


def add_examples_command(sub: Any) -> None:
    """The ``examples`` command's parser."""
    p = sub.add_parser(
        "examples",
        help="the example files the documentation uses (laws, trajectories, a URDF): list them, or --copy DIR",
    )
    p.add_argument(
        "--copy",
        metavar="DIR",
        help="write them into DIR (created if absent; a file of DIR that differs is refused, not replaced)",
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=cmd_examples)


def shipped() -> dict[str, tuple[str, bytes]]:
    """File name → (what it is, its bytes) of every shipped example."""
    import twolink_pin.examples as examples

    folder = resources.files("twolink_pin.examples")
    return {name: (what, folder.joinpath(name).read_bytes()) for name, what in examples.FILES.items()}


def cmd_examples(args: argparse.Namespace) -> int:
    from twolink_pin.cli.output import emit
    from twolink_pin.files import atomic_write, check_replaceable

    files = shipped()
    written: list[str] = []
    if args.copy is not None:
        folder = Path(args.copy)
        for name, (_, content) in files.items():
            target = folder / name
            check_replaceable(target)
            if target.exists():
                if target.read_bytes() == content:
                    continue
                raise OutputError(
                    str(target),
                    "differs from the shipped example; refusing to replace it (yours?) — move it, or give another folder",
                )
            with atomic_write(target, "wb") as f:  # all or none: the command's files move into place together
                f.write(content)
            written.append(str(target))
    rows = [{"name": name, "what": what, "bytes": len(content)} for name, (what, content) in files.items()]
    width = max(len(name) for name in files)
    lines = [f"  {row['name']:<{width}}  {row['what']}" for row in rows]
    if args.copy is not None:
        kept = len(files) - len(written)
        lines.append(
            f"copied {len(written)} file(s) into {args.copy}"
            + (f" ({kept} already there, identical)" if kept else "")
            + f"; the documentation's commands read them as {Path(args.copy).name}/NAME from {Path(args.copy).parent}"
        )
    else:
        lines.append(
            "twolink-pin examples --copy examples: write them where the documentation's commands read them"
        )
    emit(args, {"examples": rows, "copied": written}, "\n".join(lines))
    return 0


__all__ = ["add_examples_command", "cmd_examples", "shipped"]
