"""The URDF primitives the 3-D view makes itself (``visualization._drawables.primitive``) are the
geometries Pinocchio's ``MeshcatVisualizer.loadPrimitive`` makes (the second method), and writing
an animation no longer imports Pinocchio's visualizers (Viser and trimesh: ~1 s of start-up)."""

from __future__ import annotations

import subprocess
import sys
import warnings

import coal
import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from twolink_pin.model import load_robot
from twolink_pin.visualization._drawables import drawables_of, primitive

SIZE = st.floats(1e-3, 3.0, allow_nan=False)


def _pinocchio_geometry(shape: object) -> object:
    from pinocchio.visualize import MeshcatVisualizer

    model = pin.Model()
    geom = pin.GeometryModel()
    geom.addGeometryObject(pin.GeometryObject("o", 0, pin.SE3.Identity(), shape))
    return MeshcatVisualizer(model, None, geom).loadPrimitive(geom.geometryObjects[0])


def _lowered(g: object) -> tuple[dict, np.ndarray, str]:
    data = dict(g.lower({}))  # type: ignore[attr-defined]
    data.pop("uuid")
    return data, np.asarray(g.intrinsic_transform()), type(g).__mro__[1].__name__  # type: ignore[attr-defined]


def _same(shape: object) -> None:
    ours, theirs = _lowered(primitive(shape)), _lowered(_pinocchio_geometry(shape))
    assert ours[0] == theirs[0]
    np.testing.assert_array_equal(ours[1], theirs[1])


@settings(max_examples=25, deadline=None)
@given(x=SIZE, y=SIZE, z=SIZE)
def test_a_box_is_pinocchios_box(x: float, y: float, z: float) -> None:
    _same(coal.Box(x, y, z))


@settings(max_examples=25, deadline=None)
@given(radius=SIZE, length=SIZE)
def test_a_cylinder_is_pinocchios_cylinder_about_z(radius: float, length: float) -> None:
    _same(coal.Cylinder(radius, length))
    # about z: the intrinsic turn takes three.js's y axis (the cylinder's) to z
    axis = np.asarray(primitive(coal.Cylinder(radius, length)).intrinsic_transform())[:3, :3] @ [
        0.0,
        1.0,
        0.0,
    ]
    np.testing.assert_array_equal(axis, [0.0, 0.0, 1.0])


@settings(max_examples=25, deadline=None)
@given(radius=SIZE)
def test_a_sphere_is_pinocchios_sphere(radius: float) -> None:
    _same(coal.Sphere(radius))


def test_another_shape_goes_to_pinocchios_loader() -> None:
    """A capsule is no URDF primitive: not made here, drawn as Pinocchio draws it (a mesh)."""
    capsule = coal.Capsule(0.05, 0.3)
    assert primitive(capsule) is None
    robot = load_robot("twolink")
    geom = pin.GeometryModel()
    geom.addGeometryObject(pin.GeometryObject("c", 0, pin.SE3.Identity(), capsule))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a shape Pinocchio draws: no "unsupported" warning
        (drawable,) = drawables_of(robot, geom)
    assert drawable is not None
    made, expected = drawable.make(), _pinocchio_geometry(capsule)
    assert type(made).__name__ == type(expected).__name__
    np.testing.assert_array_equal(made.vertices, expected.vertices)  # type: ignore[attr-defined]


@pytest.mark.slow
def test_writing_the_twolinks_animation_imports_no_pinocchio_visualizer(tmp_path) -> None:
    """The twolink's URDF (boxes, cylinders, a sphere) is drawn without ``pinocchio.visualize``
    (nor Viser, nor trimesh) in the process."""
    script = f"""
import sys
import numpy as np
from twolink_pin.model import load_robot
from twolink_pin.visualization import write_html
robot = load_robot("twolink")
t = np.linspace(0.0, 1.0, 11)
q = np.column_stack([t, -t])
write_html(robot, t, q, q, path={str(tmp_path / "a.html")!r})
loaded = sorted(m for m in ("pinocchio.visualize", "viser", "trimesh") if m in sys.modules)
print(",".join(loaded))
"""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
    assert (tmp_path / "a.html").stat().st_size > 10_000
