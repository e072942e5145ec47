"""3-D view of an arm's motion in the browser, with meshcat.

Three ways to look at a run, all built from the same scene:

* :func:`write_html` writes one self-contained HTML file (three.js, meshcat's viewer and
  the whole animation inlined; it opens from ``file://`` and makes no network request);
* :func:`serve` starts a meshcat server on the loopback interface and plays the motion in
  the browser in real time (:class:`LiveViewer`, a context manager);
* :func:`inline_animation` shows the page of :func:`write_html` in a notebook's output
  (an ``<iframe srcdoc>``: it plays in the saved notebook, without a server).

=======================  ======================================================================
``motion.py``            the caller's arrays checked and resampled to frames (``prepare_motion``)
``scene.py``             the scene from Pinocchio geometry: arm, ghost, trail, desired path,
                         via markers, floor grid, camera; :func:`visual_model`,
                         :func:`ghost_visual_model`, the node names; the recorded commands
``_drawables.py``        how each geometry object is drawn: a mesh's triangles, a URDF primitive
                         (box, cylinder, sphere) made without importing Pinocchio's visualizers
``camera.py``            where the camera looks from, and the floor grid sized to the motion
``html.py``              msgpack packing and the self-contained page: :func:`write_html`,
                         :func:`scene_page`
``notebook.py``          the page in a notebook cell: :func:`inline_animation`
``server.py``            the live viewer: :func:`serve`, :class:`LiveViewer`
``_meshcat_bridge.py``   what leans on meshcat 0.3.2's internals: its server bound to one
                         address, its shutdown, its import
=======================  ======================================================================

Works for any arm Pinocchio loads from URDF (any number of joints, meshes found through
``package://`` or relative paths). This package only receives arrays (times [s], joint
angles [rad], positions [m]) and imports nothing to its right in the package's data flow.
It is the only part of twolink-pin that imports meshcat, lazily, inside the functions:
importing it loads neither meshcat nor a server.
"""

from twolink_pin.visualization.html import scene_page, write_html
from twolink_pin.visualization.notebook import InlineAnimation, inline_animation
from twolink_pin.visualization.scene import (
    ARM_NODE,
    CAMERA_NODE,
    CAMERA_TARGET_NODE,
    DESIRED_PATH_NODE,
    GHOST_NODE,
    GRID_NODE,
    TRAIL_NODE,
    VIA_NODE,
    ghost_visual_model,
    visual_model,
)
from twolink_pin.visualization.server import LiveViewer, serve

__all__ = [
    "ARM_NODE",
    "CAMERA_NODE",
    "CAMERA_TARGET_NODE",
    "DESIRED_PATH_NODE",
    "GHOST_NODE",
    "GRID_NODE",
    "TRAIL_NODE",
    "VIA_NODE",
    "InlineAnimation",
    "LiveViewer",
    "ghost_visual_model",
    "inline_animation",
    "scene_page",
    "serve",
    "visual_model",
    "write_html",
]
