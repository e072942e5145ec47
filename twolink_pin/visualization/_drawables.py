"""How each geometry object of an arm is drawn in meshcat (:class:`Drawable`,
:func:`drawables_of`): a mesh from the triangles Pinocchio loaded, a URDF's primitive shapes
(box, cylinder, sphere) as meshcat geometries (:func:`primitive`), any other shape through
Pinocchio's ``MeshcatVisualizer.loadPrimitive``.

:func:`primitive` makes the geometries that loader makes, without importing
``pinocchio.visualize``: importing any of its visualizers imports the package's ``__init__`` and
with it Viser and trimesh, about 1 s of start-up (``python -X importtime``) in every process that
writes an animation (the report's main process among them) for three one-line conversions.
``tests/test_visualization_primitives.py`` compares the lowered geometries with Pinocchio's; a
capsule, cone, ellipsoid or plane (from an SDF or a MJCF) still goes through Pinocchio's loader.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Callable
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from twolink_pin.model import RobotModel

CYLINDER_AXIS = np.array(
    [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
"""three.js draws a cylinder about its y axis, coal about its z axis: the rotation between them
(Pinocchio's loader applies the same)."""


URDF_PRIMITIVES = (coal.Box, coal.Cylinder, coal.Sphere)
"""The shapes :func:`primitive` makes (exact types: a subclass goes to Pinocchio's loader)."""


def primitive(shape: Any) -> Any:
    """The meshcat geometry of a coal ``Box``, ``Cylinder`` or ``Sphere`` (sizes [m]), else None."""
    import meshcat.geometry as mg

    kind = type(shape)
    if kind is coal.Box:
        return mg.Box(tuple((2.0 * np.asarray(shape.halfSide)).tolist()))
    if kind is coal.Sphere:
        return mg.Sphere(shape.radius)
    if kind is coal.Cylinder:
        return _rotated_cylinder()(2.0 * shape.halfLength, shape.radius)
    return None


@functools.cache
def _rotated_cylinder() -> type:
    """meshcat's cylinder turned about x to coal's (the URDF's) z axis (one class, made at first use:
    meshcat is imported lazily)."""
    import meshcat.geometry as mg

    class RotatedCylinder(mg.Cylinder):
        def intrinsic_transform(self) -> np.ndarray:
            return CYLINDER_AXIS

    return RotatedCylinder


class Drawable:
    """One geometry object as meshcat draws it: a geometry (or a whole object) and whether
    the object's ``meshScale`` still has to be applied by its transform."""

    def __init__(self, make: Callable[[], Any], scaled_by_transform: bool, corners: np.ndarray) -> None:
        self.make = make
        """Builds a fresh meshcat geometry (or ``mg.Object``)."""
        self.scaled_by_transform = scaled_by_transform
        self.corners = corners
        """Corners of the drawn geometry's local bounding box [m], shape (8, 3) (or (0, 3))."""


def _box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The 8 corners of the box ``lo <= p <= hi`` [m], shape (8, 3); none if it is unbounded."""
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        return np.empty((0, 3))
    return np.array(list(itertools.product(*zip(lo, hi))), dtype=float)


def drawables_of(robot: RobotModel, geom: pin.GeometryModel) -> list[Drawable | None]:
    """How to draw each object of ``geom`` (``None``: a kind meshcat cannot show)."""
    import meshcat.geometry as mg

    out: list[Drawable | None] = []
    for obj in geom.geometryObjects:
        shape = obj.geometry
        if isinstance(shape, coal.BVHModelBase):
            vertices = np.asarray(shape.vertices(), dtype=np.float32).reshape(-1, 3)
            faces = np.array(
                [[t[0], t[1], t[2]] for t in (shape.tri_indices(k) for k in range(shape.num_tris))],
                dtype=np.uint32,
            ).reshape(-1, 3)
            if len(faces) == 0:
                out.append(None)
                continue
            corners = _box_corners(vertices.min(axis=0).astype(float), vertices.max(axis=0).astype(float))
            out.append(
                Drawable(functools.partial(mg.TriangularMeshGeometry, vertices, faces), False, corners)
            )
            continue
        # a URDF primitive made here; another shape (or a kind meshcat cannot show: None) by Pinocchio
        make = (
            functools.partial(primitive, shape)
            if type(shape) in URDF_PRIMITIVES
            else _pinocchio_loader(robot, geom, obj)
        )
        if make is None:
            out.append(None)
            continue
        shape.computeLocalAABB()
        corners = _box_corners(np.array(shape.aabb_local.min_), np.array(shape.aabb_local.max_))
        out.append(Drawable(make, True, corners))
    return out


def _pinocchio_loader(
    robot: RobotModel, geom: pin.GeometryModel, obj: pin.GeometryObject
) -> Callable[[], Any] | None:
    """Pinocchio's ``loadPrimitive`` for a shape that is not a URDF primitive (:func:`primitive`),
    None (after its warning) for one meshcat cannot show."""
    from pinocchio.visualize import MeshcatVisualizer

    loader = MeshcatVisualizer(robot.model, None, geom)
    if loader.loadPrimitive(obj) is None:  # warns, as Pinocchio does
        return None
    return functools.partial(loader.loadPrimitive, obj)
