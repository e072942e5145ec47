"""The report's files from its results: ``index.html`` (a Jinja2 template shipped with the
package, autoescaped), ``report.md``, ``comparison.csv`` and ``results.json``.

Every number on the page goes through :func:`fmt` (a stated number of significant digits,
:data:`DIGITS`; 6 in tables of coefficients and in the errata's evidence), never ``str()``
of a float. Each law's docstring is shown as the documentation site shows it: Markdown with
its formulas as MathML (:func:`twolink_pin.mathml.docstring_html`), drawn by the browser
with no script.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import jinja2
import markupsafe
import numpy as np

from twolink_pin.contact_metrics import CONTACT_TITLES, CONTACT_UNITS
from twolink_pin.files import atomic_write, write_json
from twolink_pin.mathml import docstring_html, latex_to_mathml
from twolink_pin.metrics import NORMS, SIGNALS
from twolink_pin.studies.comparison import headers
from twolink_pin.task_metrics import TASK_TITLES, TASK_UNITS

DIGITS = 4
"""Significant digits of the numbers on the page (tables of coefficients: 6)."""


def fmt(x: Any, digits: int = DIGITS) -> str:
    """``x`` to ``digits`` significant digits; lists element-wise; None as "—"."""
    if x is None:
        return "—"
    if isinstance(x, (list, tuple, np.ndarray)):
        return "(" + ", ".join(fmt(v, digits) for v in x) + ")"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, (int, float, np.floating, np.integer)):
        value = float(x)
        if value == 0:
            return "0"
        if abs(value) >= 1e-3 and abs(value) < 1e6:
            return f"{value:.{digits}g}"
        return f"{value:.{max(1, digits - 1)}e}"
    return str(x)


def evidence_text(evidence: dict[str, Any]) -> str:
    """An erratum's evidence, one ``key: value`` line each, numbers to 6 digits."""
    lines = []
    for key, value in evidence.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            shown = fmt(value, 6)
        elif isinstance(value, list):
            shown = fmt(value, 6)
        elif isinstance(value, dict):
            shown = ", ".join(f"{k}: {fmt(v, 6)}" for k, v in value.items())
        else:
            shown = str(value)
        lines.append(f"{key}: {shown}")
    return "\n".join(lines)


def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("twolink_pin.report", "templates"),
        autoescape=jinja2.select_autoescape(["html"]),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["fmt"] = fmt
    env.filters["evidence"] = evidence_text
    env.filters["docstring"] = lambda text: markupsafe.Markup(docstring_html(text))
    env.filters["math"] = lambda tex: markupsafe.Markup(latex_to_mathml(tex, display=True))
    env.filters["inline_math"] = lambda tex: markupsafe.Markup(latex_to_mathml(tex))
    return env


def _comparison_rows(r: dict[str, Any], kind: str) -> list[list[str]]:
    """One row per law: its name, the plant it ran on (as compare's table says it), its norms."""
    plants = r["comparison"].get("plants", {})
    rows = []
    for name, entry in r["controllers"].items():
        m = entry["metrics"][kind]
        rows.append([name, plants.get(name, ""), *(fmt(x) for part, _, _ in SIGNALS for x in m[part])])
    return rows


def _discussion(r: dict[str, Any]) -> dict[str, Any] | None:
    twolink = r.get("twolink")
    if not twolink or "report_table2" not in twolink:
        return None
    names = [n for n in r["controllers"] if n in twolink["report_table2"]]
    if len(names) < 2:
        return None
    ours = {n: r["controllers"][n]["metrics"]["rms"]["e"][0] for n in names}
    rep = {n: twolink["report_table2"][n][0] for n in names}
    return {"ours": sorted(names, key=lambda n: ours[n]), "report": sorted(names, key=lambda n: rep[n])}


def figure_captions(folder: Path) -> dict[str, str]:
    """File name → caption of the PNG figures in ``folder``: the title each carries (what the
    figure says it shows, written by :func:`twolink_pin.plotting._save.save_figure`)."""
    from PIL import Image  # matplotlib's own dependency

    captions = {}
    for path in sorted(folder.glob("*.png")) if folder.is_dir() else ():
        try:
            with Image.open(path) as image:
                title = getattr(image, "text", {}).get("Title")
        except (OSError, ValueError):
            continue
        if isinstance(title, str) and title.strip():
            captions[path.name] = title
    return captions


def html(r: dict[str, Any], captions: dict[str, str] | None = None) -> str:
    """``index.html`` of results ``r``; ``captions`` (figure file → caption, the file's name
    where none)."""
    nv = r["robot"]["nv"]
    tables = {
        kind: {
            "title": NORMS[kind][0],
            "headers": ["controller", "plant", *headers(nv, kind)],
            "rows": _comparison_rows(r, kind),
        }
        for kind in NORMS
    }
    return (
        _environment()
        .get_template("report.html")
        .render(
            r=r,
            tables=tables,
            task_table=_task_table(r),
            contact_table=_contact_table(r),
            discussion=_discussion(r),
            nv=nv,
            limits=_limits_tables(r, nv),
            captions=captions or {},
            s2s=sim_to_sim_table(r),
        )
    )


def sim_to_sim_table(r: dict[str, Any]) -> dict[str, Any] | None:
    """The section "Sim-to-sim" as one table (a row per law and plant) with its texts; None
    without the section."""
    section = r.get("sim_to_sim")
    if not section:
        return None
    headers = [
        "controller",
        "plant",
        "RMS ‖e‖ [rad]",
        "max |e| [rad]",
        "Δ RMS ‖e‖ [rad]",
        "Δ max |e| [rad]",
    ]
    rows = []
    for law in section["laws"]:
        for row in law["rows"]:
            if not row["finished"]:
                rows.append([law["law"], row["row"], "—", "—", "—", f"did not finish: {row['failed']}"])
                continue
            deltas = [row.get("delta_rms_e"), row.get("delta_max_e")]
            shown = ["" if row is law["rows"][0] else _signed(d) for d in deltas]
            label = row["row"] + (" — cannot act here, not rerun" if row.get("derived") else "")
            rows.append([law["law"], label, fmt(row["rms_e"]), fmt(row["max_e"]), *shown])
    every = {
        "all": section.get("all", True),
        "effects_alone": section.get("effects_alone", []),
    }  # older files: all
    return section | every | {"headers": headers, "rows": rows}


def _signed(x: float | None) -> str:
    """A difference with its sign (``+1.2e-04``, ``−3.4e-05``); "—" for none."""
    if x is None:
        return "—"
    return ("+" if x >= 0 else "−") + fmt(abs(x))


RATIO_SYMBOLS = {"velocity": "q̇", "acceleration": "q̈", "effort": "τ"}
"""The symbol of each kind whose peak ratio the section's reference table gives."""


def _crossed(crossings: dict[str, Any]) -> str:
    """A run's crossings in a few symbols: ``q̇2 +0.361 rad/s (t = 0.076 s); τ1 +32.8 N·m
    (t = 0.001 s)`` — the limit, by how much at most, first when."""
    symbols = {"position": "q", "velocity": "q̇", "effort": "τ"}
    parts = []
    for kind, entry in crossings.items():
        for j, crossed in enumerate(entry["crossed"]):
            if crossed:
                excess, first = entry["excess"][j], entry["first_time"][j]
                parts.append(
                    f"{symbols.get(kind, kind)}{j + 1} +{fmt(excess, 3)} {entry['unit']} (t = {fmt(first, 3)} s)"
                )
    return "; ".join(parts)


def _limits_tables(r: dict[str, Any], nv: int) -> dict[str, Any] | None:
    """The section "The reference within the limits": its references' table (one row per
    reference) and its tracking table (one row per law and reference); None without it."""
    section = r.get("within_limits")
    if not section:
        return None
    refs = section["references"]
    kinds = [k for k in RATIO_SYMBOLS if any(k in ref["peak_ratio"] for ref in refs.values())]
    ref_headers = ["reference", "duration [s]"]
    ref_headers += [f"peak |{RATIO_SYMBOLS[k]}{j + 1}| / limit" for k in kinds for j in range(nv)]
    ref_headers += ["∫τᵀτ dt [N²·m²·s]", "within every limit", "file"]
    ref_rows = [
        [
            ref["title"],
            fmt(ref["duration_s"]),
            *(fmt(x) for k in kinds for x in ref["peak_ratio"].get(k, [None] * nv)),
            fmt(ref["effort_integral"]),
            fmt(ref["within_limits"]),
            ref["file"],
        ]
        for ref in refs.values()
    ]
    track_headers = ["controller", "reference", "run [s]"]
    track_headers += [f"RMS e{j + 1} [rad]" for j in range(nv)] + [f"max |e{j + 1}| [rad]" for j in range(nv)]
    track_headers += [f"last period max |e{j + 1}| [rad]" for j in range(nv)]
    track_headers += [f"max |τ{j + 1}| [N·m]" for j in range(nv)] + ["limits crossed"]
    track_rows = []
    for row in section["tracking"]:
        head = [row["law"], refs[row["reference"]]["short"], fmt(row["duration_s"])]
        if not row["finished"]:
            track_rows.append(head + ["—"] * (4 * nv) + [f"did not finish: {row['failed']}"])
            continue
        m = row["metrics"]
        cells = [
            fmt(x) for x in m["rms"]["e"] + m["max"]["e"] + m["final_period_max_abs_e"] + m["max"]["tau"]
        ]
        track_rows.append(head + cells + [_crossed(row["crossings"]) or "none"])
    return {
        "reference_headers": ref_headers,
        "reference_rows": ref_rows,
        "tracking_headers": track_headers,
        "tracking_rows": track_rows,
        "read_from_runs": any(row.get("from_report_run") for row in section["tracking"]),
    }


def _task_table(r: dict[str, Any]) -> dict[str, Any] | None:
    """The task-space laws' end-effector errors, one row per law (None without such a law)."""
    rows = [
        [name, *(fmt(entry["task_metrics"][key]) for key in TASK_UNITS)]
        for name, entry in r["controllers"].items()
        if entry.get("task_metrics")
    ]
    if not rows:
        return None
    return {
        "headers": ["controller", *(f"{TASK_TITLES[k]} [{u}]" for k, u in TASK_UNITS.items())],
        "rows": rows,
    }


def _contact_table(r: dict[str, Any]) -> dict[str, Any] | None:
    """The runs' contact metrics, one row per law (None without a scene)."""
    rows = [
        [
            name,
            *(
                "—" if entry["contact_metrics"][key] is None else fmt(entry["contact_metrics"][key])
                for key in CONTACT_UNITS
            ),
        ]
        for name, entry in r["controllers"].items()
        if entry.get("contact_metrics")
    ]
    if not rows:
        return None
    return {
        "headers": ["controller", *(f"{CONTACT_TITLES[k]} [{u}]" for k, u in CONTACT_UNITS.items())],
        "rows": rows,
    }


def markdown(r: dict[str, Any]) -> str:
    """``report.md`` of results ``r``: the main numbers, the comparison and the errata."""
    model = r["robot"]
    lines = [
        f"# twolink-pin report: {model['name']}",
        "",
        f"Generated by `{r['command_line']}` in {r['total_seconds']:.1f} s "
        f"(Pinocchio {r['versions']['pinocchio']}, numpy {r['versions']['numpy']}, Python {r['versions']['python']}).",
        "",
        "## Model",
        "",
        f"nv = {model['nv']}; parameters: "
        + ", ".join(f"{k} = {fmt(v, 6)}" for k, v in list(model["parameters"].items())[:12]),
        "",
    ]
    twolink = r.get("twolink")
    if twolink:
        check = twolink["closed_form_check"]
        lines += [
            f"Closed-form check: max |ΔM| = {check['max_abs_dM']:.2e}, max |ΔC| = {check['max_abs_dC']:.2e}.",
            "",
        ]
    lines += _equations_markdown(model.get("equations"), twolink)
    lines += [
        "## Torque check",
        "",
        r["torque_check"]["verdict"],
        "",
        "## Comparison",
        "",
        r["comparison_markdown"],
    ]
    identification = r.get("identification")
    if identification:
        lines += [
            "## Identification: why the adaptive estimates are still far from p (beside Fig. 27)",
            "",
            "| reference | cond(W) | λ_min per s | slowest averaged time constant [s] | predicted time to 5 % [s] |",
            "|---|---:|---:|---:|---:|",
        ]
        for row in identification["table"]:
            cells = (
                row["condition_number"],
                row["gram_min_eigenvalue_per_s"],
                row["slowest_time_constant_s"],
                row["predicted_time_to_5_percent_s"],
            )
            lines.append(f"| {row['title']} | " + " | ".join(fmt(x) for x in cells) + " |")
        lines.append("")
    lines += _limits_markdown(r)
    lines += _sim_markdown(r)
    if r["errata"]:
        lines += ["## Errata", ""]
        for e in r["errata"]:
            lines += [
                f"### {e['topic']}",
                "",
                f"- Report: {e['report']}",
                f"- Correct: {e['correct']}",
                "",
                "```",
                evidence_text(e["evidence"]),
                "```",
                "",
            ]
    return "\n".join(lines)


def _equations_markdown(equations: dict[str, Any] | None, twolink: dict[str, Any] | None) -> list[str]:
    """The derived equations as LaTeX (``$$…$$``), and the twolink's beside the course's."""
    if not equations:
        return []
    if not equations["shown"]:
        return ["## Equations of motion", "", equations["reason"], ""]
    lines = ["## Equations of motion, derived from the URDF", ""]
    lines += [f"$${b['latex']}$$ ({fmt(b['value'], 6)} {b['unit']})" for b in equations["base_parameters"]]
    lines += [f"$${entry}$$" for key in ("M", "C", "g") for entry in equations[key]]
    course = (twolink or {}).get("course_equations")
    if course and course["latex"]:
        lines += [
            "",
            "Written in the p they find (" + ", ".join(f"${p}$" for p in course["latex"]["p"]) + "):",
        ]
        same = all(course[k] for k in ("M", "C", "Y", "p_expressions"))
        lines.append("the report's M, C and Y, and its p in masses and lengths: " + ("yes" if same else "NO"))
    return [*lines, ""]


def _limits_markdown(r: dict[str, Any]) -> list[str]:
    """``report.md``'s lines of the section "The reference within the limits" (none without it)."""
    tables = _limits_tables(r, r["robot"]["nv"])
    if tables is None:
        return []
    lines = ["## The reference within the limits", ""]
    for heads, rows in (
        (tables["reference_headers"], tables["reference_rows"]),
        (tables["tracking_headers"], tables["tracking_rows"]),
    ):
        escaped = [[cell.replace("|", "\\|") for cell in row] for row in [heads, *rows]]
        lines += ["| " + " | ".join(escaped[0]) + " |", "|" + "---|" * len(heads)]
        lines += ["| " + " | ".join(row) + " |" for row in escaped[1:]] + [""]
    return lines + [f"- {note}" for note in r["within_limits"]["notes"]]


def _sim_markdown(r: dict[str, Any]) -> list[str]:
    """``report.md``'s lines of the section "Sim-to-sim" (none without it)."""
    table = sim_to_sim_table(r)
    if table is None:
        return []
    if not table["rows"]:
        return ["## Sim-to-sim", "", table.get("note", ""), ""]
    heads, rows = table["headers"], table["rows"]
    lines = ["## Sim-to-sim", "", "| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows]
    if not table["all"]:
        alone = ", ".join(table["effects_alone"])
        lines += [
            "",
            f"The no-effect check and each effect alone on {alone} only, the other laws on Pinocchio and with "
            "every effect; `twolink-pin report --sim-to-sim-all` runs every row of every law.",
        ]
    return (
        [*lines, "", f"Sources of the effects: {table['sources']}", ""] if table["sources"] else [*lines, ""]
    )


def write_pages(stage: Path, r: dict[str, Any]) -> None:
    """Write ``report.md``, ``comparison.csv``, ``results.json`` and ``index.html`` into ``stage``."""
    with atomic_write(stage / "report.md") as f:
        f.write(markdown(r))
    with atomic_write(stage / "comparison.csv") as f:
        f.write(r["comparison_csv"])
    write_json(
        stage / "results.json",
        {k: v for k, v in r.items() if k not in ("comparison_markdown", "comparison_csv")},
    )
    with atomic_write(stage / "index.html") as f:
        f.write(html(r, figure_captions(stage / "figures")))
