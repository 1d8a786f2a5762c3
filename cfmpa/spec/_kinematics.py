"""The arm model of DESIGN §2, one configuration at a time (the spec's own, shared with no impl).

Link k is the closed rectangle of width w around the segment joint_k -> joint_{k+1}, extended by
w/2 beyond both ends. ``theta1`` is absolute, ``theta2`` relative to link 1.
"""

from __future__ import annotations

import math

from ._scenario import Arm

__all__ = ["joints", "link_corners", "arm_corners"]

Point = tuple[float, float]


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
