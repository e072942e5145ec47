"""The model layer: an arm loaded from URDF and what the toolkit reads from it.

==========================  ================================================================
``robot.py``                :class:`RobotModel`, :func:`load_robot` (URDF → Pinocchio model)
``parameters.py``           parameter maps ``Y_p = Y_π P`` from Pinocchio's inertial parameters
``urdf_validation.py``      checks a URDF before Pinocchio sees it
``payload.py``              payload variants written as URDF (yourdfpy)
==========================  ================================================================
"""

from twolink_pin.model.robot import RobotModel, example_robot_urdf, load_robot, twolink_urdf_path

__all__ = ["RobotModel", "example_robot_urdf", "load_robot", "twolink_urdf_path"]
