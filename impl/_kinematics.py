"""Link rectangles and tool polygons for arrays of configurations (docs/model.md §2), vectorised
over leading axes. Part 0 is link 1, part 1 link 2, part 2 the tool (fixed in link 2's frame)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..spec import Arm

__all__ = ["link_rectangles", "link_reach", "part_polygons"]

FloatArray = npt.NDArray[np.float64]  # shapes noted per function: (...,) angles, (..., 4, 2) corners


def link_rectangles(arm: Arm, theta1: FloatArray, theta2: FloatArray, link: int,
                    grow: float = 0.0) -> FloatArray:
    """Corners (..., 4, 2), counter-clockwise, of link ``link`` at each configuration.

    ``grow`` enlarges the rectangle by that much on every side; the grown rectangle contains the
    link's Minkowski sum with a disk of radius ``grow``.
    """
    t1 = np.asarray(theta1, dtype=float)
    t2 = np.asarray(theta2, dtype=float)
    t1, t2 = np.broadcast_arrays(t1, t2)
    base = np.asarray(arm.base, dtype=float)
    u1 = np.stack([np.cos(t1), np.sin(t1)], axis=-1)
    elbow = base + arm.links[0] * u1
    if link == 2:
        return part_polygons(arm, t1, t2, elbow, grow)
    if link == 0:
        start, along, length = np.broadcast_to(base, elbow.shape), u1, arm.links[0]
    else:
        t12 = t1 + t2
        start, along, length = elbow, np.stack([np.cos(t12), np.sin(t12)], axis=-1), arm.links[1]
    normal = np.stack([-along[..., 1], along[..., 0]], axis=-1)
    r = arm.width / 2.0 + grow
    back = start - r * along
    front = start + (length + r) * along
    return np.stack([back - r * normal, front - r * normal, front + r * normal, back + r * normal],
                    axis=-2)


def part_polygons(arm: Arm, t1: FloatArray, t2: FloatArray, elbow: FloatArray, grow: float
                  ) -> FloatArray:
    """The tool's points (..., V, 2) at each configuration (its vertices, counter-clockwise), or
    with ``grow`` > 0 (..., 4 V, 2): each vertex moved by +-grow along the forearm and its normal,
    whose hull contains the tool's Minkowski sum with a disc of radius ``grow``."""
    if arm.tool is None:
        raise ValueError("the arm has no tool (part 3)")
    t12 = t1 + t2
    along = np.stack([np.cos(t12), np.sin(t12)], axis=-1)
    normal = np.stack([-along[..., 1], along[..., 0]], axis=-1)
    wrist = elbow + arm.links[1] * along
    local = np.asarray(arm.tool.polygon, dtype=float)                 # (V, 2), forearm frame
    if grow > 0:
        square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]) * grow
        local = (local[:, None, :] + square[None]).reshape(-1, 2)
    x, y = local[:, 0], local[:, 1]
    return (wrist[..., None, :] + x[:, None] * along[..., None, :]
            + y[:, None] * normal[..., None, :])


def link_reach(arm: Arm, link: int) -> tuple[float, float]:
    """(R_base, R_elbow): bounds on any point of the part's distance from the base and the
    elbow (the tool's: its farthest vertex, docs/model.md §2)."""
    r = arm.width / 2.0
    l1, l2 = arm.links
    if link == 2:
        if arm.tool is None:
            raise ValueError("the arm has no tool (part 3)")
        far_tool = max(float(np.hypot(l2 + x, y)) for x, y in arm.tool.polygon)
        return l1 + far_tool, far_tool
    if link == 0:
        return float(np.hypot(l1 + r, r)), 0.0
    far = float(np.hypot(l2 + r, r))
    return l1 + far, far
