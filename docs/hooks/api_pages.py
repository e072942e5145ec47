"""MkDocs hook: the API reference pages, generated from the package itself at build time.

One page per group of modules (:data:`GROUPS`). A package with ``__all__`` is shown by its
exported names (rendered by mkdocstrings from their docstrings); then each of its public
submodules, with the module docstring and only the public names it defines that are not
exported above, so every public name appears exactly once and nothing is left out. A
module that no group covers fails the build (strict mode), so a new module cannot go
undocumented. ``api/index.md`` holds the package's docstring and a table of every name in
``twolink_pin.__all__``, each linked to its entry.

The pages are made in memory (``on_files``) from griffe's view of the sources (no import):
edit :data:`GROUPS` to regroup, the docstrings to change the text.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

import griffe
from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "twolink_pin"
LOG = logging.getLogger("mkdocs.hooks.api_pages")

GROUPS: tuple[tuple[str, str, str, tuple[str, ...]], ...] = (
    ("model", "Model", "Robots from URDF, their parameters and profiles.", ("model",)),
    (
        "kinematics",
        "Kinematics",
        "Forward kinematics, Jacobians, inverse kinematics; a frame's poses at many configurations.",
        ("kinematics", "frame_poses"),
    ),
    (
        "limits",
        "Joint limits",
        "Every limit of a joint, read once; a reference checked against them, a run's crossings.",
        ("limits",),
    ),
    (
        "trajectory",
        "Trajectory",
        "Via points, polynomial references, trajectory files, the torque check.",
        ("trajectory", "feasibility"),
    ),
    ("dynamics", "Dynamics", "Every term from Pinocchio: M, C, g, RNEA, ABA, the regressor.", ("dynamics",)),
    (
        "symbolic",
        "Equations in closed form",
        "M, C, g and the regressor derived with SymPy from the URDF's tree: text, LaTeX, JSON, a numpy module.",
        ("symbolic",),
    ),
    (
        "optimal",
        "Optimisation",
        "The one optimisation core: QP solves, B-splines, transcriptions on Pinocchio's derivatives, SQP.",
        ("optimal",),
    ),
    ("controllers", "Controllers", "The law contract, the gains and the built-in laws.", ("controllers",)),
    (
        "simulation",
        "Plant and simulation",
        "The simulated arm (Pinocchio's and MuJoCo's), the effects a real arm has, what pushes back on it, the "
        "surfaces it touches, a law with its plant, a law's variants, the run description, and the engine.",
        (
            "plant",
            "plant_options",
            "arm_effects",
            "mujoco_model",
            "mujoco_plant",
            "mujoco_contact",
            "disturbances",
            "contact",
            "scenario",
            "law_variant",
            "run_spec",
            "run_rows",
            "contact_checks",
            "simulation",
        ),
    ),
    (
        "metrics",
        "Metrics",
        "RMS, L2 and max norms of a run or a batch; the end effector's errors; the contact's.",
        ("metrics", "task_metrics", "contact_metrics"),
    ),
    ("studies", "Studies", "Batches, Monte Carlo sweeps, comparisons, clusters.", ("studies",)),
    (
        "identification",
        "Identification",
        "Estimating the parameters from measured motion.",
        ("identification",),
    ),
    ("plotting", "Plotting", "Figures (the only matplotlib user).", ("plotting",)),
    (
        "visualization",
        "Visualization",
        "The 3-D view with meshcat (the only meshcat user).",
        ("visualization",),
    ),
    (
        "tuning",
        "Tuning",
        "`twolink-pin tune`: a law tuned live in the browser (the only viser user).",
        ("tuning",),
    ),
    ("report", "Report", "The one-command HTML report.", ("report",)),
    ("cli", "Command line", "`twolink-pin`, a thin shell over the library.", ("cli",)),
    ("twolink", "The twolink", "Everything specific to the course report's arm.", ("twolink",)),
    (
        "files",
        "Files, errors, arrays, math, threads, version",
        "The one writer and the input files' checks, bounded input documents, the stages a command reports, the signals it "
        "received, user code outside compute, the memory available, the exceptions, read-only "
        "arrays, LaTeX → MathML, OpenMP and BLAS threads, the version.",
        (
            "files",
            "input_files",
            "documents",
            "readiness",
            "interrupts",
            "user_code",
            "memory",
            "errors",
            "arrays",
            "small_linalg",
            "mathml",
            "openmp",
            "blas",
            "version",
        ),
    ),
)
"""``(page, title, one line, modules under twolink_pin)`` in the navigation's order."""

_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")


def _public(name: str) -> bool:
    return not name.startswith("_")


def _canonical(obj: griffe.Object | griffe.Alias) -> str:
    try:
        return obj.final_target.path if obj.is_alias else obj.path  # type: ignore[union-attr]
    except (griffe.AliasResolutionError, griffe.CyclicAliasError):
        return obj.path


def _directive(path: str, members: list[str] | bool | None, heading: int = 2) -> str:
    lines = [f"::: {path}", "    options:", f"      heading_level: {heading}"]
    if members is False:
        lines.append("      members: false")
    elif isinstance(members, list):
        lines.append("      members:")
        lines += [f"        - {name}" for name in members]
    return "\n".join(lines) + "\n"


def _module_sections(module: griffe.Module, shown: set[str]) -> list[str]:
    """Directives for ``module`` and its public submodules, each name once."""
    sections = []
    if module.exports is not None:
        exported = [str(name) for name in module.exports]
        for name in exported:
            if name in module.members:
                shown.add(_canonical(module.members[name]))
        sections.append(_directive(module.path, None))
    else:
        own = [
            name
            for name, member in module.members.items()
            if _public(name) and not member.is_alias and not member.is_module and member.path not in shown
        ]
        shown.update(module.members[name].path for name in own)
        sections.append(_directive(module.path, own or False))
    for name, member in sorted(module.members.items()):
        if not member.is_alias and member.is_module and _public(name):
            sections += _module_sections(member, shown)  # type: ignore[arg-type]
    return sections


def _summary(obj: griffe.Object | griffe.Alias) -> str:
    try:
        doc = obj.final_target.docstring if obj.is_alias else obj.docstring  # type: ignore[union-attr]
    except (griffe.AliasResolutionError, griffe.CyclicAliasError):
        doc = None
    if doc is None:
        return ""
    first = doc.value.strip().split("\n\n", 1)[0].replace("\n", " ")
    first = _ROLE.sub(lambda m: f"`{m[1].rsplit('.', 1)[-1]}`", first)
    first = first[:-1] + "." if first.endswith(":") else first  # a law's summary introduces its formula
    return first.replace("|", "\\|").replace("``", "`")


def _kind(obj: griffe.Object | griffe.Alias) -> str:
    try:
        return obj.final_target.kind.value if obj.is_alias else obj.kind.value  # type: ignore[union-attr]
    except (griffe.AliasResolutionError, griffe.CyclicAliasError):
        return "alias"


def _all_modules(module: griffe.Module) -> list[griffe.Module]:
    out = [module]
    for name, member in module.members.items():
        if not member.is_alias and member.is_module and _public(name) and name != "__main__":
            out += _all_modules(member)  # type: ignore[arg-type]
    return out


def api_pages() -> dict[str, str]:
    """``{path under docs/: Markdown}`` of every API page; logs an error per uncovered module."""
    package = griffe.load(PACKAGE, search_paths=[str(ROOT)], resolve_aliases=True, resolve_external=False)
    assert isinstance(package, griffe.Module)
    pages = {}
    covered: set[str] = {PACKAGE}
    for page, title, line, modules in GROUPS:
        shown: set[str] = set()
        body = [f"# {title}\n", f"{line}\n"]
        for name in modules:
            module = package.modules.get(name)
            if module is None:
                LOG.warning(
                    f"API page {page}: {PACKAGE}.{name} does not exist (docs/hooks/api_pages.py GROUPS)"
                )
                continue
            covered.update(m.path for m in _all_modules(module))
            body += _module_sections(module, shown)
        pages[f"api/{page}.md"] = "\n".join(body)
    for module in _all_modules(package):
        if module.path not in covered:
            LOG.warning(f"{module.path} is on no API page: add it to GROUPS in docs/hooks/api_pages.py")
    rows = ["| name | kind | summary |", "|---|---|---|"]
    for export in package.exports or []:
        name = str(export)
        member = package.members[name]
        rows.append(f"| [`{name}`][{PACKAGE}.{name}] | {_kind(member)} | {_summary(member)} |")
    pages["api/index.md"] = "\n".join(
        [
            "# API reference\n",
            "Generated from the docstrings. One page per part of the package, in the data flow's "
            "order (a module never imports one to its right). Every name below is importable "
            "from `twolink_pin` directly.\n",
            _directive(PACKAGE, False, heading=2),
            "## Names in `twolink_pin`\n",
            '<div class="api-names" markdown>\n',
            *rows,
            "\n</div>\n",
            "## Pages\n",
            *(f"- [{title}]({page}.md): {line}" for page, title, line, _ in GROUPS),
            "",
        ]
    )
    return pages


def on_files(files: Files, config: MkDocsConfig) -> Files:
    for path, text in api_pages().items():
        files.append(File.generated(config, path, content=text))
    return files
