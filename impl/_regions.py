"""Sound, monotone swept regions of a link over a joint box (docs/model.md §4).

Construction: sample the box on a lattice of angles anchored at ``anchor`` with spacing ``g``
(the box rounded outward to the lattice), take the convex hull of the link rectangles at the
lattice points, each grown by the interpolation margin ``delta`` (see ``sweep_margin``).

Margin lemma (discharged in proofs as ``Lemma.sweep_margin``; stated for spacings g1, g2 <= 3.14
rad, which the loader ensures: it refuses omega_q dt > 3.14, and every spacing used is the left
arm's omega_q dt or the right arm's h_q <= omega_q dt). Let a configuration theta lie in a
lattice cell [c1, c1 + g1] x [c2, c2 + g2]. Any point of the link at distance <= R_base from the
base and <= R_elbow from the elbow is within
    delta = g1^2/8 * R_base + g2^2/8 * R_elbow
of the convex hull of its positions at the cell's four corners. Proof: with theta2 fixed, moving
theta1 rotates the point about the base through at most g1 (< pi, so the arc's half-angle is at
most pi/2), so it stays within R_base * (1 - cos(g1/2)) <= R_base * g1^2/8 of the chord between
its two end positions; each end position, moving theta2 with theta1 fixed, rotates about the
elbow through at most g2 and stays within R_elbow * g2^2/8 of the chord between corner
positions; distance to a convex set is convex, so the two bounds add. Hence the link rectangle
at theta lies in the hull of the corner rectangles offset by delta, which the hull of the
rectangles grown by delta contains.

The margin used (``sweep_margin``) adds the snap slack SNAP * (g1 R_base + g2 R_elbow): a box end
within SNAP * g of a lattice point is rounded onto it, so a configuration may lie up to
SNAP * g_q beyond the sampled lattice in joint q, which moves any link point by at most
SNAP * g_q * R_q (a rotation through angle x moves a point at radius R by <= R x). A joint with
a single lattice point gets only that slack, not its g^2/8 term.

Monotonicity: lattice index ranges are computed by monotone float operations (correctly rounded
subtraction and division, then floor/ceil), so box A within box B gives lattice(A) within
lattice(B) for the same anchor and spacing, and the margin of A is at most that of B; the hull
of a subset lies within the hull of the superset.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ..spec import Arm, cases, ceil_of, floor_of, max_of, min_of
from ._kinematics import link_reach, link_rectangles

__all__ = [
    "SNAP",
    "convex_hull",
    "lattice_range",
    "sweep_margin",
    "swept_lattice",
    "swept_points",
    "swept_region",
    "naive_hull",
]

Polygon = npt.NDArray[np.float64]  # (V, 2), counter-clockwise, no repeated vertex
Box = tuple[tuple[float, float], tuple[float, float]]
Angles = Sequence[float] | npt.NDArray[np.float64]  # (theta1, theta2), e.g. spec.left_angles's

#: Relative tolerance for snapping a box end onto a lattice point; its cost (SNAP * g * R) is
#: added to the margin so that snapping never loses soundness.
SNAP = 1e-9
#: Above this coordinate magnitude (m) the hull's orientation tests run on scaled points.
HULL_SCALE_ABOVE = 1e100


def convex_hull(points: npt.ArrayLike) -> Polygon:
    """The convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped.

    Coordinates above HULL_SCALE_ABOVE are scaled by a power of two (exact) for the orientation
    tests, whose products would otherwise overflow and give a non-convex "hull".
    """
    pts = np.unique(np.asarray(points, dtype=float).reshape(-1, 2), axis=0)  # sorted by x, y
    if len(pts) <= 2:
        return pts
    big = float(np.abs(pts).max())
    if big > HULL_SCALE_ABOVE and np.isfinite(big):
        scale = 2.0 ** -math.frexp(big)[1]           # exact: the points keep their order
        return pts[_hull_indices(pts * scale)]
    return pts[_hull_indices(pts)]


def _hull_indices(pts: np.ndarray) -> list[int]:
    """Indices into sorted, distinct pts of their hull's vertices, counter-clockwise."""
    # Python floats, not numpy scalars: the same IEEE double operations, far less overhead.
    xs, ys = pts[:, 0].tolist(), pts[:, 1].tolist()

    def cross(o: int, a: int, b: int) -> float:
        return (xs[a] - xs[o]) * (ys[b] - ys[o]) - (ys[a] - ys[o]) * (xs[b] - xs[o])

    lower: list[int] = []
    for i in range(len(xs)):
        while len(lower) >= 2 and cross(lower[-2], lower[-1], i) <= 0:
            lower.pop()
        lower.append(i)
    upper: list[int] = []
    for i in range(len(xs) - 1, -1, -1):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], i) <= 0:
            upper.pop()
        upper.append(i)
    return lower[:-1] + upper[:-1]


def lattice_range(lo: Any, hi: Any, anchor: Any, g: Any) -> tuple[Any, Any]:
    """Lattice indices (i_lo, i_hi) with anchor + i*g covering [lo, hi], up to SNAP * g.

    Written once for floats and Z3 terms (``spec.floor_of`` and the like): Safety.region_soundness
    runs this very function on symbols, so its lattice is the one proved to cover the box."""
    def span() -> tuple[Any, Any]:
        i_lo = floor_of((lo - anchor) / g + SNAP)
        i_hi = ceil_of((hi - anchor) / g - SNAP)
        return (min_of(i_lo, i_hi), max_of(i_lo, i_hi))
    return cases(g <= 0, lambda: (0, 0), span)


def sweep_margin(arm: Arm, link: int, g: Sequence[float], moving: Sequence[bool] = (True, True)
                 ) -> float:
    """delta = g1^2/8 R_base + g2^2/8 R_elbow over the joints that move, plus the snap slack."""
    r_base, r_elbow = link_reach(arm, link)
    reach = (r_base, r_elbow)
    delta = 0.0
    for q in range(2):
        if moving[q]:
            delta += g[q] ** 2 / 8.0 * reach[q]
        delta += SNAP * g[q] * reach[q]
    return delta


def swept_region(arm: Arm, link: int, box: Box, anchor: Angles, g: Sequence[float], *,
                 margin_scale: float = 1.0) -> Polygon:
    """A convex polygon containing link ``link`` at every configuration in ``box`` (sound for
    ``margin_scale`` >= 1; a smaller scale exists to seed faults that the checks must catch)."""
    return convex_hull(swept_points(arm, link, box, anchor, g, margin_scale=margin_scale))


def swept_points(arm: Arm, link: int, box: Box, anchor: Angles, g: Sequence[float], *,
                 margin_scale: float = 1.0) -> npt.NDArray[np.float64]:
    """The points (P, 2) whose convex hull is ``swept_region``: the grown rectangles' corners
    at the box's lattice points."""
    t1, t2, grow = swept_lattice(arm, link, box, anchor, g, margin_scale=margin_scale)
    return link_rectangles(arm, t1, t2, link, grow=grow).reshape(-1, 2)


def swept_lattice(arm: Arm, link: int, box: Box, anchor: Angles, g: Sequence[float], *,
                  margin_scale: float = 1.0
                  ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], float]:
    """The lattice configurations (theta1, theta2 grids) sampled for ``swept_region`` and the
    margin its rectangles are grown by."""
    axes = []
    moving = []
    for q in range(2):
        if link == 0 and q == 1:
            # Link 1 does not depend on theta2: one sample suffices.
            axes.append(np.array([anchor[1]]))
            moving.append(False)
            continue
        i_lo, i_hi = lattice_range(box[q][0], box[q][1], anchor[q], g[q])
        axes.append(anchor[q] + np.arange(i_lo, i_hi + 1) * g[q])
        moving.append(i_hi > i_lo)
    t1, t2 = np.meshgrid(axes[0], axes[1], indexing="ij")
    return t1, t2, margin_scale * sweep_margin(arm, link, g, moving)


def naive_hull(arm: Arm, link: int, box: Box) -> Polygon:
    """The paper's construction: the hull of the link at the box's corner configurations (unsound)."""
    t1, t2 = np.meshgrid(np.array(box[0]), np.array(box[1]), indexing="ij")
    return convex_hull(link_rectangles(arm, t1, t2, link))
