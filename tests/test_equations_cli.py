"""``twolink-pin equations``: its outputs (text, JSON read back by SymPy, LaTeX drawn as MathML,
the numpy module), its cache, and one line with exit status 2 for every arm it refuses
(floating base, planar or unknown joint, closed chain, too many joints, --timeout)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.errors import EquationsError
from twolink_pin.model import load_robot
from twolink_pin.symbolic import MAX_JOINTS, check_urdf, derive_equations, first_joints
from twolink_pin.symbolic import cache as equations_cache

TWOLINK = Path(__file__).resolve().parents[1] / "robots" / "twolink.urdf"


@pytest.fixture(autouse=True)
def cache_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Each test its own cache folder (never the user's)."""
    folder = tmp_path / "cache"
    monkeypatch.setenv(equations_cache.ENVIRONMENT, str(folder))
    return folder


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["equations", *argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_json_strings_read_back_as_the_equations(capsys: pytest.CaptureFixture[str]) -> None:
    """--json: every expression is SymPy text that sympify reads back to the same expression,
    and its LaTeX converts to MathML (latex2mathml, as the report draws it)."""
    import sympy as sp

    from twolink_pin.mathml import latex_to_mathml

    code, out, _ = run(capsys, "--json")
    assert code == 0
    data = json.loads(out)
    eq = derive_equations(load_robot())
    names = {str(s): s for s in (*eq.q, *eq.dq, *eq.ddq, *eq.w, *eq.beta, *eq.standard)}
    names.update({"l2x": sp.Symbol("l2x", real=True), "g": sp.Symbol("g", positive=True)})
    for key, matrix in (("M", eq.M), ("C", eq.C), ("Y", eq.Y)):
        for r in range(matrix.rows):
            for c in range(matrix.cols):
                assert sp.simplify(sp.sympify(data[key][r][c], locals=names) - matrix[r, c]) == 0
                assert "<math" in latex_to_mathml(data["latex"][key][r][c])
    assert [b["definition"] for b in data["base_parameters"]] == ["Izz1 + m2*l2x**2", "mcx2", "mcy2", "Izz2"]
    assert data["zero_base_parameters"] == ["beta3"] and data["skew_symmetric"] is True


def test_python_and_latex_files(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """--python writes a module whose Y @ p_base is the twolink's RNEA; --latex a document
    whose every formula line is balanced; the text says what was written."""
    import importlib.util

    import pinocchio as pin

    module, tex = tmp_path / "twolink_equations.py", tmp_path / "twolink.tex"
    code, out, _ = run(capsys, "--python", str(module), "--latex", str(tex))
    assert code == 0 and f"wrote {tex}" in out and f"wrote {module}" in out
    spec = importlib.util.spec_from_file_location("twolink_equations", module)
    assert spec is not None and spec.loader is not None
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    robot = load_robot()
    q, v, a = np.array([0.3, 1.1]), np.array([1.5, -0.4]), np.array([0.2, -0.3])
    tau = pin.rnea(robot.model, robot.create_data(), q, v, a)
    np.testing.assert_allclose(m.Y(q, v, a) @ m.p_base, tau, rtol=0, atol=1e-12)
    document = tex.read_text(encoding="utf-8")
    assert document.count(r"\begin{align*}") == document.count(r"\end{align*}") == 5
    assert document.count("{") == document.count("}")
    assert r"M_{1,1} &= \beta_{1} + \beta_{4} + 2 \beta_{2} l_{2x} \cos{\left(q_{2} \right)}" in document


def test_the_cache_derives_once_per_kinematic_content(tmp_path: Path, cache_folder: Path) -> None:
    """A second derivation is read from the cache (same expressions); a payload (inertias only)
    shares the entry; an arm whose kinematics differ gets its own; a damaged entry is derived
    again; TWOLINK_PIN_CACHE=off keeps nothing."""
    first = derive_equations(load_robot())
    assert not first.from_cache and len(list(cache_folder.glob("*.json"))) == 1
    again = derive_equations(load_robot(payload=2.0))
    assert again.from_cache and again.M == first.M and again.Y == first.Y
    assert not np.allclose(again.beta_values, first.beta_values)
    text = TWOLINK.read_text(encoding="utf-8")
    tilted = tmp_path / "tilted.urdf"
    tilted.write_text(text.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 1 0"/>', 1), encoding="utf-8")
    other = derive_equations(load_robot(str(tilted)))
    assert not other.from_cache and len(list(cache_folder.glob("*.json"))) == 2
    for damage, path in zip(("{not json", "[1, 2]"), sorted(cache_folder.glob("*.json"))):
        path.write_text(damage, encoding="utf-8")
    assert not derive_equations(load_robot(str(tilted))).from_cache
    redone = derive_equations(load_robot())
    assert not redone.from_cache and redone.M == first.M
    assert derive_equations(load_robot()).from_cache


def test_the_cache_can_be_off(monkeypatch: pytest.MonkeyPatch, cache_folder: Path) -> None:
    monkeypatch.setenv(equations_cache.ENVIRONMENT, "off")
    assert equations_cache.cache_folder() is None
    assert not derive_equations(load_robot()).from_cache
    assert not derive_equations(load_robot()).from_cache
    assert not cache_folder.exists()


def _urdf(tmp_path: Path, name: str, joint: str) -> Path:
    """The twolink with joint2 replaced by ``joint`` (its XML)."""
    text = TWOLINK.read_text(encoding="utf-8")
    start, end = (
        text.index('<joint name="joint2"'),
        text.index("</joint>", text.index('<joint name="joint2"')),
    )
    path = tmp_path / f"{name}.urdf"
    path.write_text(text[:start] + joint + text[end + len("</joint>") :], encoding="utf-8")
    return path


REFUSED = {
    "planar": (
        '<joint name="joint2" type="planar"><parent link="link1"/><child link="link2"/>'
        '<origin xyz="0.38 0 0"/><axis xyz="0 0 1"/></joint>',
        "joint 'joint2' is planar: a planar joint (two translations and a rotation in one joint)",
    ),
    "floating": (
        '<joint name="joint2" type="floating"><parent link="link1"/><child link="link2"/></joint>',
        "joint 'joint2' is floating: a floating base (six coordinates no motor drives)",
    ),
    "spherical": (
        '<joint name="joint2" type="spherical"><parent link="link1"/><child link="link2"/></joint>',
        "joint 'joint2' is spherical: not a joint the equations derive: expected revolute, continuous or prismatic",
    ),
    "closed": (
        '<joint name="joint2" type="revolute"><parent link="link1"/><child link="link2"/>'
        '<origin xyz="0.38 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="40" velocity="10"/>'
        '</joint><joint name="loop" type="revolute"><parent link="base_link"/><child link="link2"/>'
        '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="40" velocity="10"/></joint>',
        "link 'link2' is the child of joints 'joint2' and 'loop': a closed chain",
    ),
}


@pytest.mark.parametrize("kind", list(REFUSED))
def test_a_refused_arm_is_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, kind: str
) -> None:
    joint, message = REFUSED[kind]
    path = _urdf(tmp_path, kind, joint)
    with pytest.raises(
        EquationsError, match="^" + str(path).replace(".", r"\.") + ": " + message.split(":")[0]
    ):
        check_urdf(path)
    code, out, err = run(capsys, "--robot", str(path))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and message in err, err


def test_too_many_joints_and_too_little_time(capsys: pytest.CaptureFixture[str]) -> None:
    """The Panda's 7 joints are more than MAX_JOINTS (the line says how to derive fewer);
    --joints beyond the arm is refused; a --timeout shorter than the derivation stops it with
    exit status 2 and says which bound."""
    code, _, err = run(capsys, "--robot", "panda")
    assert (
        code == 2
        and f"has 7 moving joints: the equations are derived for arms of at most {MAX_JOINTS}" in err
    )
    assert "--joints N" in err and err.count("\n") == 1
    code, _, err = run(capsys, "--joints", "3")
    assert code == 2 and "joints = 3 is invalid: expected a whole number from 1 to 2" in err
    # in a process of its own: in this one the alarm could fire inside another library's gc
    # callback (hypothesis installs one), where Python prints the exception it cannot raise
    argv = "equations --robot ur5 --joints 4 --no-cache --timeout 0.05".split()
    done = subprocess.run(
        [sys.executable, "-m", "twolink_pin_entry", *argv],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 2 and done.stdout == ""
    assert "the derivation of its 4 joints did not finish within --timeout 0.05 s" in done.stderr
    assert done.stderr.count("\n") == 1, done.stderr


def test_first_joints_holds_the_others_at_zero() -> None:
    """The UR5's first three joints: the wrist's links ride on the forearm (its mass is the
    sum), and M of the reduced arm is the full arm's upper-left block with the wrist at 0."""
    import pinocchio as pin

    ur5 = load_robot("ur5")
    arm = first_joints(ur5.model, 3)
    assert arm.nv == 3 and first_joints(ur5.model, 6) is ur5.model
    total = sum(ur5.model.inertias[j].mass for j in range(3, 7))
    assert abs(arm.inertias[3].mass - total) < 1e-12
    q = np.array([0.2, -0.7, 1.1])
    full = pin.crba(ur5.model, ur5.model.createData(), np.concatenate([q, np.zeros(3)]))
    reduced = pin.crba(arm, arm.createData(), q)
    np.testing.assert_allclose(np.triu(reduced), np.triu(full[:3, :3]), atol=1e-12)


def test_the_reports_equations_facts() -> None:
    """What the report shows: the twolink's M, C, g as LaTeX that converts to MathML; an arm of
    more joints than the page shows is a line naming the command that writes them."""
    from twolink_pin.mathml import latex_to_mathml
    from twolink_pin.report.facts import REPORT_EQUATIONS_JOINTS, equations_facts

    shown = equations_facts(load_robot())
    assert shown["shown"] and shown["zero"] == ["β3"]
    assert shown["M"][0] == r"M_{11} = \beta_{1} + \beta_{4} + 2 \beta_{2} l_{2x} \cos{\left(q_{2} \right)}"
    for latex in shown["M"] + shown["C"] + shown["g"] + [b["latex"] for b in shown["base_parameters"]]:
        assert "<math" in latex_to_mathml(latex)
    ur5 = equations_facts(load_robot("ur5"))
    assert (
        REPORT_EQUATIONS_JOINTS < 6 and not ur5["shown"] and "twolink-pin equations --robot" in ur5["reason"]
    )
