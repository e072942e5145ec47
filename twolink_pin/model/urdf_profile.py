"""A catalog robot's profile named inside a URDF the toolkit writes, so that it survives the trip.

``info --write-urdf`` (a payload variant) and ``identify --write-urdf`` (identified inertias)
write a catalog robot's URDF with other inertias. Given back with ``--urdf``, a file outside
the catalog gets the generic profile (:func:`~twolink_pin.model.profile.generic_profile`):
another end effector, home, gains and reference. So the writers add one element to the
file's ``<robot>``::

    <twolink_pin profile="ur5"/>

and :func:`~twolink_pin.model.catalog.resolve` gives a file that declares a catalog name that
robot's profile (end effector, home, locked joints, gain presets, reference, q0 offset,
mesh folders). Why an element and not a match by structure (the same joint and link names
as a catalog URDF): the declaration is explicit and visible in the file, survives copying
and renaming, is kept by a user who edits the inertias (the point of the round trip) and
dropped by deleting one line; a match by names would silently hand the UR5's home and gains
to any file that reuses its names, and lose them when a name is edited. URDF parsers ignore
elements they do not know (urdfdom, Pinocchio, yourdfpy), so the file stays a plain URDF.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

from twolink_pin.errors import InvalidURDFError
from twolink_pin.model.urdf_validation import validate_urdf_file

PROFILE_ELEMENT = "twolink_pin"
"""Tag of the element, a child of ``<robot>``, whose ``profile`` attribute names the profile."""


def declare_profile(urdf_text: str, name: str) -> str:
    """``urdf_text`` with ``<twolink_pin profile="name"/>`` as the first child of ``<robot>``
    (replacing any earlier one)."""
    root = ET.fromstring(urdf_text)
    for old in root.findall(PROFILE_ELEMENT):
        root.remove(old)
    root.insert(0, ET.Element(PROFILE_ELEMENT, profile=name))
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def declared_profile(path: str | os.PathLike[str]) -> str | None:
    """The profile name a URDF file declares, or None (no declaration, or a file that does not
    parse: the loader reports that with its own message)."""
    try:  # the project's checks first (size, no DOCTYPE/ENTITY, depth): a file is read once checked
        root = ET.fromstring(validate_urdf_file(path))
    except (InvalidURDFError, ET.ParseError):
        return None
    element = root.find(PROFILE_ELEMENT)
    return None if element is None else element.get("profile")
