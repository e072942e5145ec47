"""The package as a user installs it: the wheel built from this tree, installed into a fresh
virtual environment outside the clone; the documentation's example files come with it
(``twolink-pin examples --copy examples``) and every command of the pages that reads them runs
from a folder that is not the clone (shortened: ``--duration 0.05``, two samples, no figures).

How, offline and quick on a fresh CI machine: the wheel is built without build isolation
(``setuptools>=77`` and ``wheel`` are in the test extras, so no download); the environment is
made with ``venv --without-pip`` and the wheel installed into it by this environment's pip
(``pip --python``) with ``--no-deps --no-index``; its dependencies are this environment's
installed packages, seen through a ``.pth`` file (their folders and their hooks, not the
editable install's, which would map ``twolink_pin`` to the clone). Which ``twolink_pin`` runs
is checked. Slow tier: about a minute (a quarter of it the build).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCES = ("pyproject.toml", "README.md", "twolink_pin_entry.py", "twolink_pin", "robots", "examples")
"""What the wheel is built from (``pyproject.toml``'s packages, its readme and its module)."""

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX paths"),
]


def _run(argv: list[str], cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The ``bin`` folder of a fresh environment holding the wheel of this tree."""
    base = tmp_path_factory.mktemp("wheel")
    tree = base / "tree"
    tree.mkdir()
    for name in SOURCES:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, tree / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy(source, tree / name)
    built = _run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            "-w",
            str(base / "dist"),
            str(tree),
        ],
        base,
    )
    assert built.returncode == 0, built.stderr[-3000:]
    wheel = next((base / "dist").glob("twolink_pin-*.whl"))
    env = base / "env"
    made = _run([sys.executable, "-m", "venv", "--without-pip", str(env)], base)
    assert made.returncode == 0, made.stderr
    python = env / "bin" / "python"
    done = _run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(python),
            "install",
            "--no-deps",
            "--no-index",
            str(wheel),
        ],
        base,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    purelib = _run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], base)
    (Path(purelib.stdout.strip()) / "twolink_pin_test_dependencies.pth").write_text(_dependencies_pth())
    where = _run([str(python), "-c", "import twolink_pin; print(twolink_pin.__file__)"], base)
    assert where.returncode == 0 and where.stdout.startswith(str(env)), (where.stdout, where.stderr)
    return env / "bin"


def _dependencies_pth() -> str:
    """A ``.pth`` that gives the fresh environment this one's installed packages: their folders,
    then the hooks of this environment's ``.pth`` files (Pinocchio's ``cmeel`` prefix) but the
    editable install's (which would map ``twolink_pin`` to the clone)."""
    folders = sorted({sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]})
    hooks = [
        line
        for folder in folders
        for pth in sorted(Path(folder).glob("*.pth"))
        if not pth.name.startswith("__editable__")
        for line in pth.read_text(encoding="utf-8").splitlines()
        if line.startswith("import")
    ]
    return "\n".join([*folders, *hooks]) + "\n"


def _shortened(command: str) -> list[str]:
    """A page's command, quick: 0.05 s of simulation, two samples, no figures, no report's sections,
    an animation written to a file (not served)."""
    argv = shlex.split(command, comments=True)[1:]
    for option, value in (("--duration", "0.05"), ("--samples", "2")):
        if option in argv:
            argv[argv.index(option) + 1] = value
        elif option == "--duration" and argv[0] in ("simulate", "compare", "sweep", "animate", "report"):
            argv += [option, value]
    if "--wrench" in argv:  # its window is within the pages' 16-s runs: moved into the short one
        argv[argv.index("--wrench") + 1] = re.sub(r"@[^,]*$", "@0.01:0.02", argv[argv.index("--wrench") + 1])
    argv = [a for i, a in enumerate(argv) if a != "--plot" and (i == 0 or argv[i - 1] != "--plot")]
    if argv[0] == "animate" and "--html" not in argv:  # else it serves the motion live until stopped
        argv += ["--html", "out/animate.html"]
    if argv[0] in ("compare", "sweep"):
        argv.append("--no-plot")
    if argv[0] == "report":
        argv += ["--workers", "1", "--no-animation", "--no-limits-section"]
        if "--out" not in argv:  # its default, out/, holds the retimed reference made first: not the report's
            argv += ["--out", "out/report"]
    return argv


def _documented() -> list[str]:
    """Every ``twolink-pin`` command of the pages and the README that reads a file of
    ``examples/`` or ``out/`` (made by an earlier one), its continued lines joined."""
    found = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for block in re.findall(r"```\w*\n(.*?)```", page.read_text(encoding="utf-8"), re.S):
            # a command continued with a trailing backslash is one line, as the shell reads it
            for line in re.sub(r"\\\n\s*", " ", block).splitlines():
                served = line.startswith("twolink-pin tune ")  # a server: tests/test_tune*.py's
                if line.startswith("twolink-pin ") and "examples/" in line and not served:
                    found.append(line.strip())
    return found


VERBS = ("simulate", "animate", "compare", "sweep", "optimize", "report")
"""The cheapest first: one command per example file is run (:func:`_one_per_example`)."""


def _one_per_example(commands: list[str]) -> list[str]:
    """For each example file the pages' commands read, the cheapest command that reads it (and
    every command that reads ``out/``, made by an earlier one)."""
    rank = {verb: i for i, verb in enumerate(VERBS)}
    ordered = sorted(commands, key=lambda c: rank.get(shlex.split(c)[1], len(VERBS)))
    chosen: list[str] = []
    seen: set[str] = set()
    for command in ordered:
        files = set(re.findall(r"examples/([\w.]+)", command))
        if files - seen:
            chosen.append(command)
            seen |= files
    return chosen


def test_the_pages_use_only_shipped_examples() -> None:
    """Each ``examples/NAME`` the pages' commands read is a file ``twolink_pin.examples`` ships."""
    sys.path.insert(0, str(ROOT))
    try:
        from examples import FILES
    finally:
        sys.path.remove(str(ROOT))
    used = {m for c in _documented() for m in re.findall(r"examples/([\w.]+?\.(?:py|toml|urdf))", c)}
    assert used and used <= set(FILES), used - set(FILES)
    folder = ROOT / "examples"
    on_disk = {
        p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file() and p.name != "__init__.py"
    }
    assert set(FILES) == {name for name in on_disk if "__pycache__" not in name}


def test_the_docs_commands_run_from_the_wheel_outside_the_clone(installed: Path, tmp_path: Path) -> None:
    """``examples --copy examples`` in an empty folder, then for each example a page's command
    that reads it (the retimed reference some read made first): none is refused (exit 2) for a
    file it cannot find; a run may fail as the page says it does (exit 1)."""
    cli = str(installed / "twolink-pin")
    copied = _run([cli, "examples", "--copy", "examples"], tmp_path)
    assert copied.returncode == 0, copied.stderr
    made = _run([cli, "trajectory", "--time-optimal", "--save", "out/twolink_time_optimal.toml"], tmp_path)
    assert made.returncode == 0, made.stderr
    commands = _one_per_example(_documented())
    assert len(commands) >= 6
    for command in commands:
        argv = _shortened(command)
        done = _run([cli, *argv], tmp_path)
        assert done.returncode in (0, 1) and "internal error" not in done.stderr, (argv, done.stderr[-2000:])
