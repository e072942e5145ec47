"""Where the camera of a scene looks from, and the floor grid under the motion.

:func:`frame_camera` places the camera (from above for planar motion, facing a vertical
end-effector path, obliquely otherwise) at the least distance that keeps everything in
view; :func:`floor_grid` sizes a floor grid to the motion and clips it to what lies in front of
the camera. Both work in our axes ``(x, y, z)`` [m]; :func:`threejs_vector` converts a vector to
three.js axes ``(x, z, −y)``. Used by :mod:`.scene`.
"""

from __future__ import annotations

import math

import numpy as np

CAMERA_FOV = 75.0
"""Vertical field of view of meshcat's default camera [deg]."""
CAMERA_ASPECT = 1.6
"""Window width / height the camera is framed for (e.g. 800 × 500 px)."""
CAMERA_MARGIN = 1.1
"""The framed box fills at most 1 / CAMERA_MARGIN of the view in each direction."""
CAMERA_TILT = 0.05
"""Planar motion: camera offset towards −y per metre of height. Nearly straight down, yet
not degenerate for the orbit controls (whose up is z)."""
PLANAR_RATIO = 0.1
"""Motion whose joints' z extent is at most this fraction of their x-y extent is planar
(seen from above); any other is seen obliquely."""
OBLIQUE_AZIMUTH = 35.0
"""Oblique view: degrees from the motion's flattest horizontal direction [deg]."""
OBLIQUE_ELEVATION = 25.0
"""Oblique view: camera elevation above the horizontal [deg]."""
MIN_CAMERA_DISTANCE = 0.3
"""Closest the camera is placed to the view centre [m]."""
LEGEND_HEIGHT = 0.16
"""Part of the screen's height (of 2, in normalised device coordinates) kept free at the
bottom for the exported page's legend (the live page, without one, keeps it too)."""
CAMERA_ITERATIONS = 4
"""Passes that recentre the view on the motion's projection (perspective enlarges what is near)."""
GRID_COLORS = (0xB8BCC2, 0x80858C)
"""Grid lines, and the two lines through the base (x = 0, y = 0)."""
GRID_STEPS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 5.0, 10.0)
"""Possible grid spacings [m]."""
GRID_LINES = 12
"""The spacing is the smallest step giving at most this many lines across the motion's
largest extent (x, y or z)."""
GRID_MARGIN = 0.2
"""The grid reaches this fraction of the motion's largest extent beyond its x-y extent."""


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _path_normal(path: np.ndarray | None) -> np.ndarray | None:
    """The horizontal normal of a (nearly) planar, (nearly) vertical end-effector path,
    pointing from the base (the origin) towards the path; None for any other path."""
    if path is None or len(path) < 3:
        return None
    centred = path - path.mean(axis=0)
    values, vectors = np.linalg.eigh(centred.T @ centred)
    if values[2] <= 1e-12 or values[0] > (PLANAR_RATIO**2) * values[1]:
        return None  # a line, a point, or not planar
    normal = vectors[:, 0]
    if abs(normal[2]) > 0.5:
        return None  # a horizontal plane: the oblique view sees it well
    normal = _unit(np.array([normal[0], normal[1], 0.0]))
    return normal if normal @ path.mean(axis=0) >= 0 else -normal


def _view_direction(joints: np.ndarray, path: np.ndarray | None = None) -> np.ndarray:
    """Unit vector from the view centre towards the camera (our axes).

    Planar motion (the joints' z extent at most :data:`PLANAR_RATIO` of their x-y extent):
    from above, tilted slightly towards −y, so x points right and y up on the screen.
    A desired end-effector ``path`` in a vertical plane (a square drawn in front of the
    robot): facing that plane from the side away from the base, :data:`OBLIQUE_AZIMUTH`
    to the side and :data:`OBLIQUE_ELEVATION` above the horizontal. Otherwise obliquely,
    :data:`OBLIQUE_ELEVATION` above the horizontal and :data:`OBLIQUE_AZIMUTH` away from
    the horizontal direction in which the joints move least (the normal of a vertical plane
    of motion: never edge-on), on the −y side.
    """
    span = np.ptp(joints, axis=0)
    if span[2] <= PLANAR_RATIO * max(span[0], span[1]):
        return _unit(np.array([0.0, -CAMERA_TILT, 1.0]))
    normal = _path_normal(path)
    if normal is not None:
        azimuth = math.atan2(normal[1], normal[0]) - math.radians(OBLIQUE_AZIMUTH)
        elevation = math.radians(OBLIQUE_ELEVATION)
        return np.array(
            [
                math.cos(elevation) * math.cos(azimuth),
                math.cos(elevation) * math.sin(azimuth),
                math.sin(elevation),
            ]
        )
    xy = joints[:, :2] - joints[:, :2].mean(axis=0)
    values, vectors = np.linalg.eigh(xy.T @ xy)
    flat = vectors[:, 0] if values[1] > 1e-9 else np.array([0.0, 1.0])
    if flat[1] < 0 or (abs(flat[1]) < 1e-9 and flat[0] < 0):
        flat = -flat
    azimuth = math.atan2(-flat[1], -flat[0]) + math.radians(OBLIQUE_AZIMUTH)  # from −flat, towards +x
    elevation = math.radians(OBLIQUE_ELEVATION)
    return np.array(
        [
            math.cos(elevation) * math.cos(azimuth),
            math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )


def frame_camera(
    joints: np.ndarray, points: np.ndarray, path: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """View centre and camera position (both in our axes [m]) framing ``points``.

    Args:
        joints: Joint and end-effector positions over the motion [m], shape (P, 3): they
            decide the view direction (:func:`_view_direction`), with ``path`` (the desired
            end-effector path, shape (F, 3), if any).
        points: Everything to keep in view [m], shape (Q, 3): joints, the geometry's
            bounding-box corners over the motion, via points.

    Returns:
        ``(centre, camera)``: the point looked at, such that the points' projection is
        centred on the screen above the legend (:data:`LEGEND_HEIGHT`), and the camera
        placed along the view direction at the least distance at which every point lies
        within the field of view (vertical :data:`CAMERA_FOV`, aspect
        :data:`CAMERA_ASPECT`, :data:`CAMERA_MARGIN`).
    """
    d = _view_direction(joints, path)
    right = _unit(np.cross(-d, [0.0, 0.0, 1.0]))
    up = np.cross(right, -d)
    axes = np.array([right, up, d])  # rows: screen right, screen up, towards the camera
    local = points @ axes.T
    centre = axes.T @ (0.5 * (local.min(axis=0) + local.max(axis=0)))
    tan = np.array([CAMERA_ASPECT, 1.0]) * math.tan(math.radians(CAMERA_FOV / 2)) / CAMERA_MARGIN
    lo, hi = np.array([-1.0, -1.0 + LEGEND_HEIGHT]), np.ones(2)  # the screen's free part (x, y)

    def fit(centre: np.ndarray) -> tuple[np.ndarray, float]:
        r = (points - centre) @ axes.T
        reach = np.where(r[:, :2] > 0, hi, -lo) * tan  # per point and screen axis
        return r, max(float(np.max(r[:, 2:] + np.abs(r[:, :2]) / reach)), MIN_CAMERA_DISTANCE)

    for _ in range(CAMERA_ITERATIONS):  # perspective: near points look bigger; recentre on screen
        r, distance = fit(centre)
        screen = r[:, :2] / ((distance - r[:, 2:]) * tan)  # in [-1, 1] inside the view
        middle = 0.5 * (screen.min(axis=0) + screen.max(axis=0)) - 0.5 * (lo + hi)
        centre = centre + axes[:2].T @ (middle * distance * tan)
    _, distance = fit(centre)
    return centre, centre + distance * d


def _clip(
    a: np.ndarray, b: np.ndarray, camera: np.ndarray, forward: np.ndarray, near: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """The part of segment ``a``–``b`` at least ``near`` in front of the camera, or ``None``."""
    da, db = (a - camera) @ forward - near, (b - camera) @ forward - near
    if da < 0 and db < 0:
        return None
    if da < 0:
        a = a + (b - a) * (da / (da - db))
    elif db < 0:
        b = a + (b - a) * (da / (da - db))
    return a, b


def floor_grid(points: np.ndarray, centre: np.ndarray, camera: np.ndarray) -> tuple[float, list[np.ndarray]]:
    """A floor grid in z = 0 under ``points`` [m]: its spacing [m] and its segments.

    meshcat's own grid (20 m, 0.5 m spacing) is hidden: too coarse for an arm under a
    metre, and its lines that pass behind the camera are dropped by some WebGL renderers
    (headless Chromium's SwiftShader). This one covers the motion's x-y extent plus a
    margin, its spacing suits the arm's size, its lines fall on multiples of the spacing
    (the base is on a crossing), and every line is clipped to what lies in front of the
    camera.

    Returns:
        ``(spacing, [minor, major])``: each an array of segment end points, shape (2S, 3);
        ``major`` holds the lines x = 0 and y = 0.
    """
    extent = float(max(np.max(np.ptp(points, axis=0)), 1e-3))  # the arm's size, all three axes
    spacing = next((s for s in GRID_STEPS if extent / s <= GRID_LINES), GRID_STEPS[-1])
    lo = np.floor((points[:, :2].min(axis=0) - GRID_MARGIN * extent) / spacing) * spacing
    hi = np.ceil((points[:, :2].max(axis=0) + GRID_MARGIN * extent) / spacing) * spacing
    forward = _unit(centre - camera)
    near = 0.02 * float(np.linalg.norm(centre - camera))
    minor: list[np.ndarray] = []
    major: list[np.ndarray] = []
    for axis in (0, 1):
        for k in range(round(lo[axis] / spacing), round(hi[axis] / spacing) + 1):
            a, b = np.zeros(3), np.zeros(3)
            a[axis] = b[axis] = k * spacing
            a[1 - axis], b[1 - axis] = lo[1 - axis], hi[1 - axis]
            segment = _clip(a, b, camera, forward, near)
            if segment is not None:
                (major if k == 0 else minor).extend(segment)
    return spacing, [np.array(minor).reshape(-1, 3), np.array(major).reshape(-1, 3)]


def threejs_vector(v: np.ndarray) -> list[float]:
    """Our ``(x, y, z)`` in three.js axes ``(x, z, −y)``."""
    return [float(v[0]), float(v[2]), float(-v[1])]
