"""The model layer: an arm loaded from URDF and what the toolkit reads from it.

==========================  ================================================================
``robot.py``                :class:`RobotModel`, :func:`load_robot` (URDF → Pinocchio model)
``catalog.py``              robots by name: what ``--robot NAME|PATH`` resolves to
``registry.py``             the registry of named robots (a robot's package registers itself)
``robot_data.py``           where example-robot-data's URDFs and mesh folders are
``profile.py``              what a named robot brings beyond its URDF (home, gains, ...)
``profile_file.py``         a profile as a TOML file: any URDF, one arm of it (the catalog's, a user's)
``home.py``                 a home for an arm whose profile gives none (dexterous, mid-range)
``parameters.py``           parameter maps ``Y_p = Y_π P`` from Pinocchio's inertial parameters
``base_parameters.py``      the identifiable base parameters of any model (Gautier's QR)
``urdf_validation.py``      checks a URDF before Pinocchio sees it
``urdf_elements.py``        its checks of one link and one joint, and how URDF numbers are read
``inertia_repair.py``       the nearest physically consistent inertia (``--repair-inertias``)
``payload.py``              payload variants written as URDF (yourdfpy)
``urdf_write.py``           a URDF with other inertias and joint friction written in
==========================  ================================================================
"""

from twolink_pin.model import catalog as _catalog
from twolink_pin.model.robot import RobotModel, example_robot_urdf, load_robot, twolink_urdf_path

_catalog.register_folder(_catalog.package_folder())  # the catalog's profiles: robots/*.toml

__all__ = ["RobotModel", "example_robot_urdf", "load_robot", "twolink_urdf_path"]
