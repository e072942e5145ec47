"""Validation of URDF robot descriptions before they reach Pinocchio.

Why this module exists: Pinocchio 4.1's URDF parser (``pin.buildModelFromUrdf`` and
``pin.buildModelFromXML``, through urdfdom) does not protect its caller from bad files:

* it **segfaults** on very long kinematic chains (about 5000 links and more), killing the
  Python process with no exception to catch;
* it silently **accepts a negative mass**, an inertia matrix that is **not positive
  definite**, or one whose principal moments **violate the triangle inequality**
  (physically impossible bodies whose dynamics are nonsense);
* it silently accepts a **zero joint axis**, giving a joint that moves nothing and a
  singular mass matrix;
* it silently **drops a link's whole inertia** (mass and inertia become 0) when the mass
  value is not a number, e.g. ``"abc"`` or ``"nan"``, with only a line on stderr;
* it reports a truncated or malformed XML file only as a bare ``ValueError`` ("does not
  contain a valid URDF model"), the actual reason and line going to stderr;
* it does **not expand XML entities** (``<!ENTITY m "2.0">`` … ``value="&m;"``), while
  Python's XML parser does: a mass given through an entity would pass a validator that
  expands it and then be silently dropped by Pinocchio. A DTD or an entity is therefore
  refused, so that the validator and Pinocchio read the same document (this also refuses
  external entities and entity-expansion bombs before anything is expanded);
* it reads **UTF-8 only**: a UTF-16 file is "not a valid URDF model" with no reason.

:func:`validate_urdf_file` and :func:`validate_urdf_string` check a description with
the standard library's XML parser and numpy, and raise
:class:`~twolink_pin.errors.InvalidURDFError` on the first problem found. The error names
the file, the offending element (``link 'link2' <inertial><mass>``,
``joint 'joint2' <axis>``) and what was expected
(``mass value="-1.0" must be a finite number > 0 kg``). A description that passes gives a
sound Pinocchio model: no crash, no silent nonsense.

Checks, in order:

1. the file is a regular, readable file of at most :data:`MAX_URDF_BYTES` (a FIFO or a
   device such as ``/dev/zero`` is refused before any read), UTF-8 encoded, without a DTD
   or entity declarations, and well-formed XML whose root is ``<robot>``;
2. at least one ``<link>``, at most :data:`MAX_LINKS` links and joints (counted before
   any other work, so a huge file is rejected quickly);
3. every link and joint has a unique, non-empty ``name``;
4. every ``<inertial>`` (at most one per link): ``<mass value>`` finite and > 0 [kg]
   (or exactly 0 with an all-zero inertia: an explicitly massless frame link; a mass > 0
   with an all-zero inertia is a point mass);
   ``<inertia>`` with the six attributes ``ixx ixy ixz iyy iyz izz`` finite [kg·m²], the
   matrix positive semidefinite (a zero principal moment — a thin rod — is accepted with a
   note: the model's ``M(q)`` is checked positive definite when it is built) and its
   principal moments satisfying the triangle inequality (refused, naming the link and
   ``--repair-inertias``; with ``repair_inertias`` the nearest inertia that satisfies it is
   written in instead, :mod:`~twolink_pin.model.inertia_repair`);
   ``<origin xyz rpy>`` if present three finite numbers each [m], [rad]. A link that never
   moves (the root link, and links fixed to it through fixed joints only: a static base)
   needs finite numbers only: a mass 0 with an inertia, or an inertia that no body has, is
   accepted with a note;
5. every ``<joint>``: ``type`` one of :data:`JOINT_TYPES`; ``<origin xyz rpy>`` if present
   three finite numbers each; for revolute, continuous, prismatic and planar joints the
   ``<axis xyz>`` if present three finite numbers with a nonzero norm (URDF's default axis
   is ``1 0 0``); for revolute, continuous and prismatic joints ``<limit effort velocity>``
   if present finite and >= 0, and for revolute and prismatic joints ``<limit lower upper>``
   finite with ``lower <= upper`` (URDF defaults both to 0);
   ``<parent link>`` and ``<child link>`` name declared links, different from each other,
   and no link is the child of two joints;
6. the links form one tree: exactly one root link (no joint's child) from which every link
   is reachable (no cycles).

Numbers are read as URDF writes them: decimal literals such as ``1``, ``-0.5``, ``.5``,
``1e-3``. ``nan``, ``inf`` and Python-only spellings such as ``1_000`` are rejected.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Sequence
from typing import Final, NamedTuple

from twolink_pin.errors import InputFileError, InvalidURDFError
from twolink_pin.files import read_input_file
from twolink_pin.model.inertia_repair import InertiaRepair
from twolink_pin.model.urdf_elements import (
    AXIS_JOINT_TYPES,
    JOINT_TYPES,
    TRIANGLE_RTOL,
    check_joint,
    check_link,
    quoted_names,
)

__all__ = [
    "AXIS_JOINT_TYPES",
    "JOINT_TYPES",
    "MAX_LINKS",
    "MAX_URDF_BYTES",
    "TRIANGLE_RTOL",
    "CheckedURDF",
    "check_urdf_file",
    "validate_urdf_file",
    "validate_urdf_string",
]

MAX_URDF_BYTES: Final[int] = 32 * 2**20
"""Largest URDF file read (32 MiB; example-robot-data's arms are under 100 kB)."""

MAX_LINKS: Final[int] = 1000
"""Most links (and joints) a description may have.

Pinocchio 4.1 segfaults when parsing chains of about 5000 links; a 1000-link chain parses
correctly in a fraction of a second. The cap keeps a wide margin below the crash and far
above any arm this toolkit is meant for.
"""

MAX_DEPTH: Final[int] = 64
"""Deepest element nesting accepted (a URDF is 4 or 5 deep; Pinocchio's XML reader stops,
with lines on stderr, at a few hundred)."""

_ROBOT = "<robot>"


class CheckedURDF(NamedTuple):
    """A URDF document that passed the checks (:func:`check_urdf_file`)."""

    text: str
    """The document checked (UTF-8 text), repaired inertias written in: what Pinocchio builds."""
    notes: tuple[str, ...]
    """What was accepted with a note (a static link's mass 0, a thin rod's zero moment)."""
    repairs: tuple[InertiaRepair, ...]
    """The inertias replaced (``repair_inertias=True``), one per link."""


def check_urdf_file(path: str | os.PathLike[str], repair_inertias: bool = False) -> CheckedURDF:
    """Check that a URDF file can safely be given to Pinocchio, with what was accepted.

    Args:
        path: The URDF file.
        repair_inertias: Replace each inertia that breaks the triangle inequality by the nearest
            one that satisfies it (:mod:`~twolink_pin.model.inertia_repair`) instead of refusing it.

    Returns:
        The document checked (give its ``text`` to Pinocchio's ``buildModelFromXML``, not the file
        again, so that what is built is what was checked), its notes and repairs.

    Raises:
        InvalidURDFError: If the file is missing or unreadable (element ``file``), is not
            well-formed XML (element ``XML document``, with the parser's line and column),
            or fails any check of :func:`validate_urdf_string`. ``error.path`` is ``path``.
    """
    name = os.fsdecode(path)
    try:
        data = read_input_file(name, MAX_URDF_BYTES, "a URDF file")
    except InputFileError as err:
        raise InvalidURDFError(name, "file", err.reason) from None
    root = _parse(data, name)
    notes, repairs = _validate_robot(root, name, repair_inertias)
    text = ET.tostring(root, encoding="unicode") if repairs else data.decode("utf-8")
    return CheckedURDF(text, notes, repairs)


def validate_urdf_file(path: str | os.PathLike[str]) -> str:
    """Check that a URDF file can safely be given to Pinocchio; the document checked (UTF-8
    text), as :func:`check_urdf_file` without repairs.

    Raises:
        InvalidURDFError: see :func:`check_urdf_file`.
    """
    return check_urdf_file(path).text


def validate_urdf_string(xml: str, path: str = "<string>") -> None:
    """Check that URDF text can safely be given to Pinocchio.

    Args:
        xml: The URDF document.
        path: Name used for the document in error messages (``error.path``).

    Raises:
        InvalidURDFError: On the first problem found; see the module docstring for the
            checks. Physical quantities are SI: mass [kg], inertia [kg·m²] about the
            centre of mass, lengths [m], angles [rad].
    """
    _validate_robot(_parse(xml, path), path)


# --- document level -------------------------------------------------------------------------


_BOMS: Final[tuple[tuple[bytes, str], ...]] = (
    (b"\x00\x00\xfe\xff", "UTF-32"),
    (b"\xff\xfe\x00\x00", "UTF-32"),
    (b"\xfe\xff", "UTF-16"),
    (b"\xff\xfe", "UTF-16"),
)
_DECLARATION = re.compile(rb"<!(DOCTYPE|ENTITY)", re.IGNORECASE)


def _parse(text: str | bytes, path: str) -> ET.Element:
    data = text.encode("utf-8") if isinstance(text, str) else text
    for bom, encoding in _BOMS:
        if data.startswith(bom):
            raise InvalidURDFError(
                path,
                "XML document",
                f"is {encoding} encoded; expected UTF-8 (Pinocchio's URDF parser reads UTF-8 only)",
            )
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        raise InvalidURDFError(
            path, "XML document", f"is not valid UTF-8 (byte {err.start}, line {line}); expected a UTF-8 file"
        ) from None
    found = _DECLARATION.search(data)
    if found:
        line = data[: found.start()].count(b"\n") + 1
        raise InvalidURDFError(
            path,
            "XML document",
            f"declares a <!{found.group(1).decode().upper()}> (line {line}); expected a URDF without DTD or "
            "entities (Pinocchio's parser does not expand them, so a value given through an entity would be "
            "dropped)",
        )
    try:
        return ET.fromstring(data)
    except ET.ParseError as err:
        # str(err) is e.g. "no element found: line 12, column 4".
        raise InvalidURDFError(
            path, "XML document", f"not well-formed XML ({err}); expected a complete, well-formed XML file"
        ) from None


def _depth(root: ET.Element) -> int:
    deepest, stack = 1, [(root, 1)]
    while stack:
        element, level = stack.pop()
        deepest = max(deepest, level)
        if deepest > MAX_DEPTH:
            return deepest
        stack.extend((child, level + 1) for child in element)
    return deepest


def _validate_robot(
    robot: ET.Element, path: str, repair: bool = False
) -> tuple[tuple[str, ...], tuple[InertiaRepair, ...]]:
    if robot.tag != "robot":
        raise InvalidURDFError(path, f"<{robot.tag}>", f"root element is <{robot.tag}>; expected <robot>")
    links = robot.findall("link")
    joints = robot.findall("joint")
    # Count first: a huge file must be rejected before any per-element work.
    if len(links) > MAX_LINKS:
        raise InvalidURDFError(
            path,
            _ROBOT,
            f"has {len(links)} links, more than the cap MAX_LINKS = {MAX_LINKS}; expected at most "
            f"{MAX_LINKS} links (Pinocchio 4.1 crashes on chains of about 5000 links)",
        )
    if len(joints) > MAX_LINKS:
        raise InvalidURDFError(
            path,
            _ROBOT,
            f"has {len(joints)} joints, more than the cap MAX_LINKS = {MAX_LINKS}; expected at most "
            f"{MAX_LINKS} joints (Pinocchio 4.1 crashes on chains of about 5000 links)",
        )
    if not links:
        raise InvalidURDFError(path, _ROBOT, "contains no <link>; expected at least one link")
    if not (robot.get("name") or "").strip():
        raise InvalidURDFError(path, _ROBOT, 'has no name; expected <robot name="...">')
    if _depth(robot) > MAX_DEPTH:
        raise InvalidURDFError(
            path, _ROBOT, f"nests elements more than {MAX_DEPTH} deep; expected a URDF (4 or 5 levels)"
        )

    link_names = _names(links, "link", path)
    joint_names = _names(joints, "joint", path)
    known = set(link_names)
    edges = [
        check_joint(joint, f"joint '{name}'", link_names, known, path)
        for joint, name in zip(joints, joint_names, strict=True)
    ]
    root = _check_tree(link_names, joint_names, edges, path)
    static = _static_links(root, joints, edges)
    notes: list[str] = []
    repairs: list[InertiaRepair] = []
    for link, name in zip(links, link_names, strict=True):
        found = check_link(link, f"link '{name}'", path, static=name in static, repair=repair)
        notes += found.notes
        if found.repair is not None:
            repairs.append(found.repair)
    return tuple(notes), tuple(repairs)


def _static_links(root: str, joints: Sequence[ET.Element], edges: Sequence[tuple[str, str]]) -> set[str]:
    """The links that never move: the root link and those fixed to it through fixed joints only."""
    fixed: dict[str, list[str]] = {}
    for joint, (parent, child) in zip(joints, edges, strict=True):
        if joint.get("type") == "fixed":
            fixed.setdefault(parent, []).append(child)
    static, stack = {root}, [root]
    while stack:
        for child in fixed.get(stack.pop(), []):
            static.add(child)
            stack.append(child)
    return static


def _names(elements: Sequence[ET.Element], kind: str, path: str) -> list[str]:
    """Names of ``elements`` (all ``<link>`` or all ``<joint>``), checked present and unique."""
    names = []
    for number, element in enumerate(elements, start=1):
        name = element.get("name")
        if name is None or not name.strip():
            raise InvalidURDFError(
                path, f"{kind} #{number}", f'has no name; expected <{kind} name="..."> with a non-empty name'
            )
        names.append(name)
    for name, count in Counter(names).items():
        if count > 1:
            raise InvalidURDFError(
                path, f"{kind} '{name}'", f"name is declared {count} times; expected unique {kind} names"
            )
    return names


# --- tree -----------------------------------------------------------------------------------


def _check_tree(
    link_names: Sequence[str], joint_names: Sequence[str], edges: Sequence[tuple[str, str]], path: str
) -> str:
    """Check that the links form one tree; its root link."""
    parent_joint: dict[str, str] = {}
    children: dict[str, list[str]] = {name: [] for name in link_names}
    for joint_name, (parent, child) in zip(joint_names, edges, strict=True):
        if child in parent_joint:
            raise InvalidURDFError(
                path,
                f"joint '{joint_name}' <child>",
                f"link '{child}' is already the child of joint '{parent_joint[child]}'; "
                "expected each link to be the child of at most one joint",
            )
        parent_joint[child] = joint_name
        children[parent].append(child)

    roots = [name for name in link_names if name not in parent_joint]
    if not roots:
        raise InvalidURDFError(
            path,
            _ROBOT,
            "has no root link: every link is the child of a joint, so the joints form a cycle; "
            "expected exactly one link that is no joint's child",
        )
    if len(roots) > 1:
        raise InvalidURDFError(
            path,
            _ROBOT,
            f"has {len(roots)} root links ({quoted_names(roots)}); expected exactly one link that is no "
            "joint's child (the links must form one connected tree)",
        )

    root = roots[0]
    reached = {root}
    stack = [root]
    while stack:
        for child in children[stack.pop()]:
            if child not in reached:
                reached.add(child)
                stack.append(child)
    for name in link_names:
        if name not in reached:
            raise InvalidURDFError(
                path,
                f"link '{name}'",
                f"is not connected to root link '{root}': its joints form a cycle; expected a tree",
            )
    return root
