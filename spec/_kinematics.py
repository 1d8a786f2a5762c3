"""The arm model of docs/model.md §2, one configuration at a time (the spec's own, shared with no impl).

Link k is the closed rectangle of width w around the segment joint_k -> joint_{k+1}, extended by
w/2 beyond both ends. ``theta1`` is absolute, ``theta2`` relative to link 1.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ._arith import hypot_of
from ._scenario import Arm

__all__ = ["LINK_WORDS", "joints", "link_corners", "arm_corners", "corners", "link_name", "reach"]

Point = tuple[float, float]

#: Link numbers as docs/model.md §2 names them: 1-based, link 1 the upper arm, link 2 the forearm.
LINK_WORDS = {1: "upper arm", 2: "forearm"}


def link_name(arm: str, number: int) -> str:
    """``left link 2 (forearm)``: the words every message, JSON text and table uses for link
    ``number`` (1-based: 1 upper arm, 2 forearm; docs/model.md §2) of the ``arm`` side."""
    if arm not in ("left", "right") or number not in LINK_WORDS:
        raise ValueError(f"no link {number!r} of arm {arm!r} (arms left/right, links 1 and 2)")
    return f"{arm} link {number} ({LINK_WORDS[number]})"


def joints(arm: Arm, theta: tuple[float, float]) -> tuple[Point, Point, Point]:
    """Base, elbow and tip positions of ``arm`` at joint angles ``theta``."""
    bx, by = arm.base
    t1, t12 = theta[0], theta[0] + theta[1]
    ex, ey = bx + arm.links[0] * math.cos(t1), by + arm.links[0] * math.sin(t1)
    tx, ty = ex + arm.links[1] * math.cos(t12), ey + arm.links[1] * math.sin(t12)
    return (bx, by), (ex, ey), (tx, ty)


def link_corners(arm: Arm, theta: tuple[float, float], link: int) -> list[Point]:
    """The four corners (counter-clockwise) of link ``link`` (0 or 1) at ``theta``."""
    pts = joints(arm, theta)
    (ax, ay), (bx, by) = pts[link], pts[link + 1]
    phi = theta[0] if link == 0 else theta[0] + theta[1]
    ux, uy = math.cos(phi), math.sin(phi)
    r = arm.width / 2.0
    # Extend along the link by r past both joints, then offset by r to either side.
    p0 = (ax - r * ux, ay - r * uy)
    p1 = (bx + r * ux, by + r * uy)
    nx, ny = -uy * r, ux * r
    return [(p0[0] - nx, p0[1] - ny), (p1[0] - nx, p1[1] - ny),
            (p1[0] + nx, p1[1] + ny), (p0[0] + nx, p0[1] + ny)]


def arm_corners(arm: Arm, theta: tuple[float, float]) -> list[list[Point]]:
    """Both links' corners: the arm as two rectangles."""
    return [link_corners(arm, theta, 0), link_corners(arm, theta, 1)]


def reach(arm: Arm, link: int) -> tuple[float, float]:
    """(R_base, R_elbow): no point of the link is farther than these from the base / the elbow.

    Runs on floats and on Z3 terms (``hypot_of``): proofs/_obl_constants.py proves these bounds of
    the rectangle of docs/model.md §2 and the certificate's and the tube's speeds built on them."""
    r = arm.width / 2
    if link == 0:
        return hypot_of(arm.links[0] + r, r), 0.0
    far = hypot_of(arm.links[1] + r, r)
    return arm.links[0] + far, far


def corners(arm: Arm, t1: npt.ArrayLike, t2: npt.ArrayLike, link: int, r: float
            ) -> npt.NDArray[np.float64]:
    """Corners (..., 4, 2) of the link at (t1, t2) as a rectangle of half-width r, capped by r."""
    t1 = np.asarray(t1, dtype=float)
    t2 = np.asarray(t2, dtype=float)
    bx, by = arm.base
    ex = bx + arm.links[0] * np.cos(t1)
    ey = by + arm.links[0] * np.sin(t1)
    if link == 0:
        px, py, phi = np.full_like(ex, bx), np.full_like(ey, by), t1
        qx, qy = ex, ey
    else:
        phi = t1 + t2
        px, py = ex, ey
        qx, qy = ex + arm.links[1] * np.cos(phi), ey + arm.links[1] * np.sin(phi)
    ux, uy = r * np.cos(phi), r * np.sin(phi)
    pts = [(px - ux + uy, py - uy - ux), (qx + ux + uy, qy + uy - ux),
           (qx + ux - uy, qy + uy + ux), (px - ux - uy, py - uy + ux)]
    return np.stack([np.stack(p, -1) for p in pts], -2)
