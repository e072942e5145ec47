"""The model layer: an arm loaded from URDF and what the toolkit reads from it.

==========================  ================================================================
``robot.py``                :class:`RobotModel`, :func:`load_robot` (URDF → Pinocchio model)
``catalog.py``              robots by name: the registry ``--robot NAME`` resolves
``example_robots.py``       example-robot-data's arms in the catalog (UR5, Panda, ...)
``profile.py``              what a named robot brings beyond its URDF (home, gains, ...)
``parameters.py``           parameter maps ``Y_p = Y_π P`` from Pinocchio's inertial parameters
``base_parameters.py``      the identifiable base parameters of any model (Gautier's QR)
``urdf_validation.py``      checks a URDF before Pinocchio sees it
``urdf_elements.py``        its checks of one link and one joint, and how URDF numbers are read
``payload.py``              payload variants written as URDF (yourdfpy)
``urdf_write.py``           a URDF with other inertias and joint friction written in
==========================  ================================================================
"""

from twolink_pin.model import example_robots as _example_robots  # noqa: F401  # registers them
from twolink_pin.model.robot import RobotModel, example_robot_urdf, load_robot, twolink_urdf_path

__all__ = ["RobotModel", "example_robot_urdf", "load_robot", "twolink_urdf_path"]
