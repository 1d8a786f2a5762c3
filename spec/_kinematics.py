"""The arm model of docs/model.md §2, one configuration at a time (the spec's own, shared with no impl).

Link k is the closed rectangle of width w around the segment joint_k -> joint_{k+1}, extended by
w/2 beyond both ends. ``theta1`` is absolute, ``theta2`` relative to link 1. An arm's parts are
its links and, if it has one, its tool (part index 2, 0-based): a convex polygon fixed in the
forearm's frame (origin at the end of link 2, x along the forearm). Two parts, one of each arm,
can touch only if their closed height intervals overlap (``heights_overlap``; docs/model.md §2,
"Tools and heights").
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ._arith import hypot_of
from ._scenario import Arm

__all__ = ["LINK_WORDS", "TOOL", "joints", "link_corners", "arm_corners", "corners", "link_name",
           "reach", "parts", "part_points", "arm_parts", "part_height", "heights_overlap", "height_gap",
           "pairs_to_test"]

Point = tuple[float, float]

#: Link numbers as docs/model.md §2 names them: 1-based, link 1 the upper arm, link 2 the forearm.
LINK_WORDS = {1: "upper arm", 2: "forearm"}
#: The tool's part index (0-based, after link 1 = 0 and link 2 = 1); 1-based it is part 3.
TOOL = 2


def link_name(arm: str, number: int) -> str:
    """``left link 2 (forearm)``, ``right tool``: the words every message, JSON text and table
    uses for part ``number`` (1-based: 1 upper arm, 2 forearm, 3 the tool; docs/model.md §2)
    of the ``arm`` side."""
    if arm not in ("left", "right") or number not in (*LINK_WORDS, TOOL + 1):
        raise ValueError(f"no part {number!r} of arm {arm!r} (arms left/right, links 1 and 2, "
                         "tool 3)")
    if number == TOOL + 1:
        return f"{arm} tool"
    return f"{arm} link {number} ({LINK_WORDS[number]})"


def parts(arm: Arm) -> tuple[int, ...]:
    """The arm's part indices (0-based): (0, 1), and 2 if it carries a tool."""
    # getattr: the proofs' symbolic arms carry only what the constants read (no tool).
    return (0, 1, TOOL) if getattr(arm, "tool", None) is not None else (0, 1)


def part_height(arm: Arm, part: int) -> tuple[float, float] | None:
    """The part's closed height interval (m), or None: it may be at any height."""
    if part == TOOL:
        return arm.tool.z if arm.tool is not None else None
    z = getattr(arm, "z", None)
    return z[part] if z is not None else None


def heights_overlap(a: tuple[float, float] | None, b: tuple[float, float] | None) -> bool:
    """Whether two closed height intervals share a point (None overlaps every height)."""
    if a is None or b is None:
        return True
    return a[0] <= b[1] and b[0] <= a[1]


def height_gap(a: tuple[float, float] | None, b: tuple[float, float] | None) -> float:
    """The vertical distance between two closed height intervals (0 where they overlap)."""
    if a is None or b is None:
        return 0.0
    return max(0.0, a[0] - b[1], b[0] - a[1])


def pairs_to_test(left: Arm, right: Arm) -> tuple[tuple[int, int], ...]:
    """The (left part, right part) pairs that can touch: their heights overlap. A cell of D_R
    is blocked iff the regions of some such pair are within eps (docs/model.md §4)."""
    return tuple((a, b) for a in parts(left) for b in parts(right)
                 if heights_overlap(part_height(left, a), part_height(right, b)))


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
    """(R_base, R_elbow): no point of the part is farther than these from the base / the elbow.

    Runs on floats and on Z3 terms (``hypot_of``): proofs/_obl_constants.py proves these bounds of
    the rectangle of docs/model.md §2 and the certificate's and the tube's speeds built on them.
    For the tool (part 2): its farthest vertex from the elbow (a point of a convex polygon is a
    convex combination of its vertices, and distance is convex), and l1 more from the base."""
    r = arm.width / 2
    if link == TOOL:
        if arm.tool is None:
            raise ValueError("the arm has no tool")
        far = max(hypot_of(arm.links[1] + x, y) for x, y in arm.tool.polygon)
        return arm.links[0] + far, far
    if link == 0:
        return hypot_of(arm.links[0] + r, r), 0.0
    far = hypot_of(arm.links[1] + r, r)
    return arm.links[0] + far, far


def part_points(arm: Arm, t1: npt.ArrayLike, t2: npt.ArrayLike, part: int, grow: float = 0.0
                ) -> npt.NDArray[np.float64]:
    """Points (..., P, 2) whose convex hull contains the part at (t1, t2) grown by ``grow``
    (its Minkowski sum with a disc of radius ``grow``): a link's rectangle of half-width
    w/2 + grow (``corners``), or the tool's vertices each moved by +-grow along the forearm and
    its normal (the sum with a square of half-side ``grow``, which holds the disc)."""
    if part != TOOL:
        return corners(arm, t1, t2, part, arm.width / 2 + grow)
    if arm.tool is None:
        raise ValueError("the arm has no tool")
    t1 = np.asarray(t1, dtype=float)
    t2 = np.asarray(t2, dtype=float)
    bx, by = arm.base
    phi = t1 + t2
    c, s = np.cos(phi), np.sin(phi)
    wx = bx + arm.links[0] * np.cos(t1) + arm.links[1] * c
    wy = by + arm.links[0] * np.sin(t1) + arm.links[1] * s
    steps = [(0.0, 0.0)] if grow == 0 else [(-grow, -grow), (grow, -grow), (grow, grow),
                                             (-grow, grow)]
    pts = [(wx + (x + dx) * c - (y + dy) * s, wy + (x + dx) * s + (y + dy) * c)
           for x, y in arm.tool.polygon for dx, dy in steps]
    return np.stack([np.stack(p, -1) for p in pts], -2)


def arm_parts(arm: Arm, theta: tuple[float, float]) -> list[list[Point]]:
    """Every part's outline at ``theta``: the two link rectangles, then the tool's polygon."""
    out = arm_corners(arm, theta)
    if arm.tool is not None:
        pts = part_points(arm, theta[0], theta[1], TOOL)
        out.append([(float(x), float(y)) for x, y in pts])
    return out


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
