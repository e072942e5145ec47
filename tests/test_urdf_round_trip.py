"""A URDF written by --write-urdf for a catalog robot, given back with --urdf: the same inertias
and the same profile (model/payload.py, model/urdf_profile.py, model/catalog.py).

Independent checks: every body's spatial inertia of the reloaded file against the in-memory
payload variant ``load_robot(name, payload=m)`` (Pinocchio's model, not the writer's numbers);
the profile fields against the catalog's; the run (gains, start, torques) against the
catalog robot's run with the same payload.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from twolink_pin.cli import main
from twolink_pin.model import catalog, load_robot

ARMS = catalog.names()


def _write(name: str, tmp_path: Path, payload: float = 2.0) -> Path:
    out = tmp_path / f"{name}_payload.urdf"
    assert main(["info", "--robot", name, "--payload", str(payload), "--write-urdf", str(out)]) == 0
    return out


@pytest.mark.parametrize("name", ARMS)
def test_every_catalog_arms_payload_variant_is_written_with_the_in_memory_inertias(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    written = load_robot(_write(name, tmp_path))
    in_memory = load_robot(name, payload=2.0)
    assert written.model.nv == in_memory.model.nv
    for j in range(1, in_memory.model.njoints):
        np.testing.assert_allclose(
            written.model.inertias[j].toDynamicParameters(),
            in_memory.model.inertias[j].toDynamicParameters(),
            rtol=1e-12,
            atol=1e-12,
        )
    np.testing.assert_allclose(written.p, in_memory.p, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("name", ARMS)
def test_a_written_urdf_keeps_the_catalog_robots_profile(name: str, tmp_path: Path) -> None:
    written = load_robot(_write(name, tmp_path))
    own = load_robot(name)
    assert written.name == name and written.ee_frame == own.ee_frame
    np.testing.assert_array_equal(written.home, own.home)
    np.testing.assert_array_equal(written.torque_limits, own.torque_limits)
    np.testing.assert_array_equal(written.model.lowerPositionLimit, own.model.lowerPositionLimit)
    assert written.profile.q0_offset == own.profile.q0_offset
    assert written.profile.gain_presets == own.profile.gain_presets
    assert written.profile.trajectory == own.profile.trajectory
    assert written.profile.locked_joints == own.profile.locked_joints


def test_the_ur5_written_with_a_payload_runs_as_the_ur5_with_that_payload(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Same gains, same start, same torques: the run is the catalog robot's with --payload 2."""
    path = _write("ur5", tmp_path)
    capsys.readouterr()
    runs = []
    for robot in (["--urdf", str(path)], ["--robot", "ur5", "--payload", "2"]):
        assert main(["simulate", "pd", *robot, "--duration", "0.2", "--json"]) == 0
        runs.append(json.loads(capsys.readouterr().out))
    for key in ("gains", "q0_offset", "metrics", "peak_torque", "torque_limits", "p_true"):
        _assert_same(runs[0][key], runs[1][key], key)
    assert runs[0]["robot"] == runs[1]["robot"] == "ur5"


def _assert_same(a: object, b: object, where: str) -> None:
    if isinstance(b, dict):
        assert isinstance(a, dict) and set(a) == set(b), where
        for k in b:
            _assert_same(a[k], b[k], f"{where}.{k}")
    elif isinstance(b, list) or isinstance(b, (int, float)):
        np.testing.assert_allclose(
            np.asarray(a, dtype=float), np.asarray(b, dtype=float), rtol=1e-9, atol=1e-12, err_msg=where
        )
    else:
        assert a == b, where


def test_a_file_without_the_declaration_keeps_the_generic_profile(tmp_path: Path) -> None:
    path = _write("ur5", tmp_path)
    text = path.read_text()
    assert '<twolink_pin profile="ur5" />' in text
    bare = tmp_path / "bare.urdf"
    bare.write_text(text.replace('<twolink_pin profile="ur5" />', ""))
    robot = load_robot(bare)
    assert robot.name == "bare" and robot.ee_frame != "tool0"
