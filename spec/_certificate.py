"""The continuous-time certificate (docs/model.md §7): no contact at ANY instant of the executed motion.

Executed motion. The principal (left) arm follows ``left_angles``: synchronised PTP, arriving at
Tf, then at rest. The subordinate (right) arm is at cell L_k at time k dt, moves linearly in
joint space from L_k to L_{k+1} during [k dt, (k+1) dt], and rests at the last cell afterwards.
The motion ends, for both, at T_end = max((len - 1) dt, Tf); after it nothing moves.

The bound. For link a of the left arm and link b of the right arm let d_ab(t) be the Euclidean
distance between their closed rectangles (``link_corners``). On a time interval where joint
velocities are constant, every point p of a link moves with speed

    |dp/dt| = |w1 J(p - base) + w2 J(p - elbow)| <= |w1| R_base + |w2| R_elbow = v

(J is the quarter turn; R_base bounds |p - base| over the link: sqrt((l1 + w/2)^2 + (w/2)^2)
for link 1 and l1 + sqrt((l2 + w/2)^2 + (w/2)^2) for link 2; R_elbow bounds |p - elbow|: 0 for
link 1, sqrt((l2 + w/2)^2 + (w/2)^2) for link 2). Left joint speeds are |goal - start| / Tf
before Tf and 0 after; right joint speeds on segment k are |angle(L_{k+1}) - angle(L_k)| / dt,
and 0 after the path ends. So each rectangle moves by at most v |t - s| in Hausdorff distance,
and d_ab is Lipschitz with constant L_ab = v_a + v_b. On [t0, t1], from the samples at both ends,

    d_ab(t) >= max(d_ab(t0) - L_ab (t - t0), d_ab(t1) - L_ab (t1 - t))
            >= (d_ab(t0) + d_ab(t1) - L_ab (t1 - t0)) / 2.

(This is never weaker than the midpoint test d(mid) > L (t1 - t0) / 2 applied to the same
interval split at its midpoint.) An interval is proved clear when the least such bound over the
four link pairs exceeds EPS = 1e-9 m, a margin far above the float rounding (~1e-15 m) in the
sampled positions and distances. Intervals are the motion's pieces (split at multiples of dt and
at Tf, where velocities change), halved until proved clear; a sample at distance 0 is a contact.
An interval still unproved at ``max_depth`` halvings is reported undecided, never clear. So is,
at once, an atomic interval that is not proved: one of zero length (an all-static motion is the
single instant [0, 0]), one whose midpoint rounds to an end, or one on which nothing moves
(L_ab = 0, so d_ab is constant and the bound is the sample itself). Halving could not tighten
its bound; a sampled distance in (0, EPS] there is within rounding of a touch, so neither proved
clear nor a contact.
The least of the proved interval bounds is a lower bound on the clearance over the whole motion.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
import numpy.typing as npt

from ..errors import CertificateViolation, InputError
from ._grid import EPS, Grid, exact_tf, left_angles
from ._kinematics import height_gap, link_name, part_height, part_points, parts, reach
from ._polygon import polygon_distances
from ._scenario import Arm, Scenario

__all__ = [
    "Certificate",
    "ContactDetail",
    "certify",
    "certificate_json",
    "closest_links",
    "part_distances",
    "pose_distance",
    "contact_links_text",
    "contact_parts",
    "prove_motion",
    "Prover",
    "require_clear",
    "interval_bound",
    "link_speeds",
    "link_rects",
    "pair_lipschitz",
    "DEFAULT_MAX_DEPTH",
    "DEFAULT_BOUND_RATIO",
    "DEFAULT_MAX_INTERVALS",
]

#: Halvings of one motion piece (a dt step) before giving up: dt / 2^24 is ~1e-9 s at dt = 0.02.
DEFAULT_MAX_DEPTH = 24
#: After an interval is proved clear it is still halved while its bound is below this fraction
#: of the least sampled clearance, so that lower_bound_m comes out near min_m (0: stop at proof).
DEFAULT_BOUND_RATIO = 0.9
#: Work cap: once this many intervals have been examined, what is still unproved is undecided.
DEFAULT_MAX_INTERVALS = 2_000_000

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]
Contact = tuple[float, tuple[int, int]]


@dataclass(frozen=True)
class ContactDetail:
    """Where a sampled contact is: the instant, the parts (left, right), numbered 1-based as in
    docs/model.md §2 (1 the upper arm, 2 the forearm, 3 the tool), both arms' joint angles then,
    and the path segment the subordinate was on (``step`` k: moving from cells[0] to cells[1]
    during [k dt, (k+1) dt]; ``step`` None: resting at its last cell, cells[0] == cells[1])."""

    t_s: float
    links: tuple[int, int]
    left_angles_rad: tuple[float, float]
    right_angles_rad: tuple[float, float]
    step: int | None
    cells: tuple[tuple[int, int], tuple[int, int]]

    @property
    def segment(self) -> str:
        """``step 4->5`` or ``resting at the last cell (step 7)``, as violations print it."""
        return "resting at the last cell" if self.step is None else (
            f"step {self.step}->{self.step + 1}")


@dataclass(frozen=True)
class Certificate:
    """Whether the executed motion is contact-free at every instant, and by how much.

    ``clear`` is True only when every interval was proved clear; then ``lower_bound_m`` (> EPS)
    is THE PROVED figure: a lower bound on the distance between the arms over the whole motion
    (else 0.0). ``min_clearance_m`` / ``t_min_s`` are only the least SAMPLED distance and its
    instant: an upper bound on the true minimum, not a guarantee. ``contact`` is
    (t, (left part, right part)) for a sampled contact, parts numbered 1-based
    (``closest_links``; 3 the tool), and ``contact_detail`` the same with the
    angles and path segment; ``undecided`` lists the merged (t0, t1) intervals left unproved.
    """

    clear: bool
    min_clearance_m: float
    t_min_s: float
    lower_bound_m: float
    intervals: int
    contact: Contact | None
    undecided: tuple[tuple[float, float], ...]
    samples: int
    max_depth_used: int
    contact_detail: ContactDetail | None = None


def certify(scenario: Scenario, grid: Grid, path: Sequence[Sequence[int]], *,
            max_depth: int = DEFAULT_MAX_DEPTH, bound_ratio: float = DEFAULT_BOUND_RATIO,
            max_intervals: int = DEFAULT_MAX_INTERVALS) -> Certificate:
    """Prove (or refute) that ``path`` executed with the principal's PTP motion never has contact.

    The bound is stated in the module docstring. Each dt piece is halved at most ``max_depth``
    times and at most ``max_intervals`` intervals are examined; what is unproved at a cap is
    undecided (``clear`` False). A proved interval is still halved while its bound is below
    ``bound_ratio`` times the least sampled clearance, to make ``lower_bound_m`` informative.
    A found contact stops the search; its instant is the earliest sampled contact at that point
    (a contact instant, not necessarily the first). Cells need not be neighbours (a jump is a
    fast linear move): adjacency is is_path's business, not the certificate's.
    """
    cells = _check_path(path, grid)
    if isinstance(max_depth, bool) or not isinstance(max_depth, int) or max_depth < 0:
        raise InputError("max_depth", max_depth, "must be an integer >= 0")
    if not 0.0 <= bound_ratio < 1.0:
        raise InputError("bound_ratio", bound_ratio, "must lie in [0, 1)")
    return prove_motion(_Motion.of(scenario, grid, cells), max_depth=max_depth,
                        bound_ratio=bound_ratio, max_intervals=max_intervals)


def prove_motion(motion: Any, *, max_depth: int = DEFAULT_MAX_DEPTH,
                 bound_ratio: float = DEFAULT_BOUND_RATIO,
                 max_intervals: int = DEFAULT_MAX_INTERVALS,
                 first_contact: bool = False) -> Certificate:
    """The proof loop of the module docstring, shared by the grid path's motion and a trajectory.

    ``motion`` gives ``pieces()``, ``lipschitz(seg, moving)``, ``distances(t, seg)`` and
    ``detail(contact, seg)``, and may give ``end_distances(t0, t1, seg)``: both ends' distances
    at once, the same values as two ``distances`` calls (fewer computed). With
    ``first_contact`` a found contact does not stop the search: every interval before it is
    still decided (halved down to ``max_depth``), so the contact reported is the first one, to
    within a piece's length / 2^max_depth.
    """
    prover = Prover(max_depth=max_depth, bound_ratio=bound_ratio, max_intervals=max_intervals,
                    first_contact=first_contact)
    prover.add(motion)
    return prover.certificate()


class Prover:
    """The proof loop over a motion given in parts (``add``, in time order), keeping only
    aggregates between parts: the least sampled distance, the first contact and its detail,
    the proved lower bound, counts and the merged undecided intervals. One part is exactly
    ``prove_motion``. With several, the loop runs part by part: the halving threshold
    ``bound_ratio`` x (least sampled distance) and the work cap ``max_intervals`` see what the
    parts so far sampled and examined, not what later parts will, so ``intervals``, ``samples``,
    ``max_depth_used``, ``lower_bound_m`` and the sampled minimum may differ from one part of
    the same pieces; every proved interval is proved all the same (its bound is its own), so
    ``clear`` can differ only through the work cap. Parts must follow one another in time (a
    part starts no earlier than the previous ended): once a contact is found, later parts
    cannot hold an earlier one and are skipped (neither sampled nor counted)."""

    def __init__(self, *, max_depth: int = DEFAULT_MAX_DEPTH,
                 bound_ratio: float = DEFAULT_BOUND_RATIO,
                 max_intervals: int = DEFAULT_MAX_INTERVALS, first_contact: bool = False) -> None:
        self.max_depth, self.bound_ratio = max_depth, bound_ratio
        self.max_intervals, self.first_contact = max_intervals, first_contact
        self.best = _Best(math.inf, 0.0, None)
        self.examined = 0
        self.samples = 0
        self.proved_lb = math.inf
        self.deepest = 0
        self.undecided: list[list[float]] = []        # merged, in time order
        self.detail: ContactDetail | None = None

    def add(self, motion: Any) -> bool:
        """Decide ``motion``'s pieces; True when this part holds the contact reported."""
        if self.best.contact is not None:
            return False
        first_contact, max_depth = self.first_contact, self.max_depth
        t0, t1, seg, moving = motion.pieces()
        lip = motion.lipschitz(seg, moving)                       # (K, 2, 2)
        ends = getattr(motion, "end_distances", None)
        d0, d1 = ends(t0, t1, seg) if ends else (motion.distances(t0, seg),
                                                 motion.distances(t1, seg))
        depth = np.zeros(len(t0), dtype=np.int64)
        self.samples += 2 * len(t0)

        best = self.best.update(np.concatenate([t0, t1]), np.concatenate([d0, d1]),
                                np.concatenate([seg, seg]), earliest=first_contact)
        self.examined += len(t0)
        undecided: list[tuple[FloatArray, FloatArray]] = []
        while best.contact is None or first_contact:
            if best.contact is not None:            # only what lies before it can come earlier
                before = t0 < best.contact[0]
                if not np.any(before):
                    break
                t0, t1, seg, d0, d1, lip, depth = (x[before] for x in (t0, t1, seg, d0, d1, lip,
                                                                        depth))
            self.deepest = max(self.deepest, int(depth.max()))
            lb = np.min(interval_bound(d0, d1, lip, (t1 - t0)[:, None, None]), axis=(1, 2))
            proved = lb > EPS
            tm = (t0 + t1) / 2.0
            # Halving cannot tighten an atomic interval's bound: it has no interior instant (zero
            # length, or no float between its ends) or nothing moves on it (L = 0, d constant).
            # Its samples decide it; splitting it would only double it every round up to the caps.
            atomic = (tm <= t0) | (tm >= t1) | np.all(lip == 0.0, axis=(1, 2))
            at_cap = depth >= max_depth
            over_budget = self.examined + 2 * len(t0) > self.max_intervals
            settled = proved & (at_cap | over_budget | atomic | (lb >= self.bound_ratio * best.d))
            stuck = ~proved & (at_cap | over_budget | atomic)
            if np.any(settled):
                self.proved_lb = min(self.proved_lb, float(lb[settled].min()))
            if np.any(stuck):
                undecided.append((t0[stuck], t1[stuck]))
            split = ~(settled | stuck)
            if not np.any(split):
                break
            t0, t1, tm, seg, d0, d1, lip, depth = (x[split] for x in (t0, t1, tm, seg, d0, d1,
                                                                       lip, depth))
            dm = motion.distances(tm, seg)
            self.samples += len(tm)
            best = best.update(tm, dm, seg, earliest=first_contact)
            t0, t1 = np.concatenate([t0, tm]), np.concatenate([tm, t1])
            d0, d1 = np.concatenate([d0, dm]), np.concatenate([dm, d1])
            seg, lip = np.concatenate([seg, seg]), np.concatenate([lip, lip])
            depth = np.concatenate([depth, depth]) + 1
            self.examined += len(t0)
        self.best = best
        # This part's intervals lie after the previous parts': merging them onto the list is
        # merging them all (_merge).
        for a, b in _merge(undecided):
            if self.undecided and a <= self.undecided[-1][1]:
                self.undecided[-1][1] = max(self.undecided[-1][1], b)
            else:
                self.undecided.append([a, b])
        if best.contact is None:
            return False
        self.detail = motion.detail(best.contact, best.contact_seg)
        return True

    def certificate(self) -> Certificate:
        """The certificate of the parts added so far."""
        best, merged = self.best, tuple((a, b) for a, b in self.undecided)
        clear = best.contact is None and not merged
        return Certificate(
            clear=clear,
            min_clearance_m=best.d,
            t_min_s=best.t,
            lower_bound_m=self.proved_lb if clear else 0.0,
            intervals=self.examined,
            contact=best.contact,
            undecided=merged,
            samples=self.samples,
            max_depth_used=self.deepest,
            contact_detail=self.detail,
        )


def certificate_json(cert: Certificate) -> dict[str, Any]:
    """plan.json's ``clearance`` (docs/model.md §9). ``min_m`` / ``t_s`` (stable keys) are the least
    SAMPLED distance and its instant, an upper bound on the true minimum; ``lower_bound_m`` is
    the PROVED lower bound over every instant (> 1e-9 when ``clear``, else 0.0)."""
    contact = None
    if cert.contact is not None:
        contact = {"t_s": cert.contact[0], "links": list(cert.contact[1]),
                   "links_text": contact_links_text(cert.contact[1]),
                   "parts": contact_parts(cert.contact[1])}
        c = cert.contact_detail
        if c is not None:
            contact.update(left_angles_rad=list(c.left_angles_rad),
                           right_angles_rad=list(c.right_angles_rad), step=c.step,
                           segment=c.segment, cells=[list(x) for x in c.cells])
    return {
        "min_m": cert.min_clearance_m,
        "t_s": cert.t_min_s,
        "clear": cert.clear,
        "lower_bound_m": cert.lower_bound_m,
        "intervals": cert.intervals,
        "samples": cert.samples,
        "max_depth_used": cert.max_depth_used,
        "contact": contact,
        "undecided": [list(iv) for iv in cert.undecided],
    }


def closest_links(d: FloatArray) -> tuple[int, int]:
    """(left part, right part) of the least of ``d[a, b]`` (parts x parts), the distances between
    left part index a and right part index b: as part NUMBERS, 1-based (docs/model.md §2: 1 the
    upper arm, 2 the forearm, 3 the tool), the one place an array index becomes a part number."""
    a, b = np.unravel_index(int(np.argmin(d)), d.shape)
    return int(a) + 1, int(b) + 1


def contact_parts(links: Sequence[int]) -> list[str]:
    """``["left tool", "right link 2 (forearm)"]``: the left and the right part of a contact or
    closest pair, 1-based part numbers (``closest_links``) in words (``link_name``,
    docs/model.md §2); the JSON's ``parts``."""
    return [link_name("left", int(links[0])), link_name("right", int(links[1]))]


def contact_links_text(links: Sequence[int]) -> str:
    """``left link 2 (forearm) and right tool`` for 1-based part numbers (3 the tool)."""
    return " and ".join(contact_parts(links))


def require_clear(cert: Certificate, *, name: str = "continuous-time certificate") -> None:
    """Raise CertificateViolation unless the certificate proved the motion clear."""
    if cert.clear:
        return
    if cert.contact is not None:
        t, (a, b) = cert.contact
        values: dict[str, Any] = {"t_s": t, "links": contact_links_text((a, b)),
                                  "distance_m": 0.0}
        c = cert.contact_detail
        if c is not None:
            values.update({"left angles_rad": list(c.left_angles_rad),
                           "right angles_rad": list(c.right_angles_rad),
                           "path segment": c.segment,
                           "cells": [list(x) for x in c.cells]})
        # A tool is a polygon, not a link rectangle (docs/model.md §2): say "parts" then. The
        # parts are named in the one line too (a batch listing shows that line alone).
        text = ("the arms' link rectangles touch during the motion" if max(a, b) <= 2 else
                "the arms' parts touch during the motion") + f": {contact_links_text((a, b))}"
        raise CertificateViolation(name, text, values, condition_id="certificate.contact",
                                   message=text)
    first = cert.undecided[0] if cert.undecided else None
    text = "some time intervals could be neither proved clear nor shown in contact"
    raise CertificateViolation(name, text, condition_id="certificate.undecided", message=text,
                               values={"undecided intervals": len(cert.undecided),
                                       "first interval_s": first,
                                       "min sampled distance_m": cert.min_clearance_m})


def _check_path(path: Sequence[Sequence[int]], grid: Grid) -> IntArray:
    try:
        cells = [tuple(c) for c in path]
    except TypeError:
        raise InputError("path", path, "must be a list of [i, j] cells") from None
    if not cells:
        raise InputError("path", [], "must have at least one cell")
    for k, c in enumerate(cells):
        if (len(c) != 2 or any(isinstance(x, bool) or not isinstance(x, (int, np.integer))
                               for x in c)):
            raise InputError(f"path[{k}]", list(c), "must be a pair of integers [i, j]")
        if not (0 <= c[0] < grid.m and 0 <= c[1] < grid.n):
            raise InputError(f"path[{k}]", [int(x) for x in c],
                             f"must lie in the grid [0, {grid.m - 1}] x [0, {grid.n - 1}]")
    return np.asarray(cells, dtype=np.int64)


@dataclass(frozen=True)
class _Best:
    """The least sampled clearance so far, its instant, and the earliest sampled contact (with
    the path segment of the interval it was sampled in)."""

    d: float
    t: float
    contact: Contact | None
    contact_seg: int = -1

    @staticmethod
    def of(t: FloatArray, d: FloatArray, seg: IntArray) -> _Best:
        return _Best(math.inf, 0.0, None).update(t, d, seg)

    def update(self, t: FloatArray, d: FloatArray, seg: IntArray, *,
               earliest: bool = False) -> _Best:
        """With ``earliest``, a sampled contact before the one held replaces it."""
        if len(t) == 0:
            return self
        arm = d.min(axis=(1, 2))
        k = int(np.argmin(arm))
        best = self if self.d <= arm[k] else _Best(float(arm[k]), float(t[k]), self.contact,
                                                   self.contact_seg)
        touching = np.flatnonzero(arm == 0.0)
        if best.contact is None and len(touching):
            first = touching[np.argmin(t[touching])]
            contact = (float(t[first]), closest_links(d[first]))
            best = _Best(0.0, contact[0], contact, int(seg[first]))
        elif earliest and best.contact is not None and len(touching):
            first = touching[np.argmin(t[touching])]
            if float(t[first]) < best.contact[0]:
                contact = (float(t[first]), closest_links(d[first]))
                best = _Best(0.0, contact[0], contact, int(seg[first]))
        return best


@dataclass(frozen=True)
class _Motion:
    """The executed motion of both arms, sampled in batches."""

    scenario: Scenario
    dt: float
    tf: float
    path_angles: FloatArray          # (len, 2)
    cells: IntArray                  # (len, 2)

    @staticmethod
    def of(s: Scenario, g: Grid, cells: IntArray) -> _Motion:
        angles = np.stack([g.lo[0] + cells[:, 0] * g.h[0], g.lo[1] + cells[:, 1] * g.h[1]], axis=1)
        return _Motion(s, g.dt, float(exact_tf(s)), angles, cells)

    def pieces(self) -> tuple[FloatArray, FloatArray, IntArray, npt.NDArray[np.bool_]]:
        """Intervals on which both arms' joint velocities are constant: (t0, t1, seg, moving).

        ``seg`` is the right arm's path segment (-1 once it rests); ``moving`` is whether the left
        arm moves. Segments are assigned by construction, not recovered from float times.
        """
        dt, tf, last = self.dt, self.tf, len(self.path_angles) - 1
        # One piece too many is harmless (dropped below); one too few would lose motion.
        ks = np.arange(max(last, math.ceil(tf / dt) + 1), dtype=np.int64)
        t0, t1 = ks * dt, (ks + 1) * dt
        seg = np.where(ks < last, ks, -1)
        keep = (ks < last) | (t0 < tf)                      # nothing moves after T_end
        t0, t1, seg = t0[keep], np.where(ks[keep] < last, t1[keep], np.minimum(t1[keep], tf)), seg[keep]
        cut = (t0 < tf) & (tf < t1)                         # the left arm stops inside the piece
        t0 = np.concatenate([t0, np.full(np.count_nonzero(cut), tf)])
        t1 = np.concatenate([np.where(cut, tf, t1), t1[cut]])
        seg = np.concatenate([seg, seg[cut]])
        if len(t0) == 0:                                    # nothing moves at all
            t0, t1, seg = np.zeros(1), np.zeros(1), np.full(1, -1, dtype=np.int64)
        order = np.argsort(t0, kind="stable")
        t0, t1, seg = t0[order], t1[order], seg[order]
        # cast: numpy's stubs type an int array times a float as floating[Any]
        return cast(FloatArray, t0), cast(FloatArray, t1), seg, t0 < tf

    def lipschitz(self, seg: IntArray, moving: npt.NDArray[np.bool_]) -> FloatArray:
        """L_ab = v_a (left part a) + v_b (right part b) per piece, shape (K, parts, parts)."""
        s = self.scenario
        left_w = np.abs(np.subtract(s.left.goal, s.left.start)) / self.tf if self.tf > 0 else np.zeros(2)
        wl = np.where(moving[:, None], left_w[None, :], 0.0)
        steps = np.abs(np.diff(self.path_angles, axis=0)) / self.dt      # (len - 1, 2)
        if len(steps) == 0:                       # a one-cell path: the right arm never moves
            steps = np.zeros((1, 2))
        wr = np.where(seg[:, None] >= 0, steps[np.maximum(seg, 0)], 0.0)
        vl = link_speeds(s.left, wl)                                    # (K, 2)
        vr = link_speeds(s.right, wr)
        return pair_lipschitz(vl[:, :, None], vr[:, None, :])

    def right_angles(self, t: FloatArray, seg: IntArray) -> FloatArray:
        a = self.path_angles
        if len(a) == 1:
            return np.broadcast_to(a[0], (len(t), 2))
        k = np.maximum(seg, 0)
        u = np.clip((t - k * self.dt) / self.dt, 0.0, 1.0)[:, None]
        moving = a[k] + u * (a[k + 1] - a[k])
        return np.where(seg[:, None] >= 0, moving, a[-1])

    def detail(self, contact: Contact, seg: int) -> ContactDetail:
        """The contact with both arms' angles at its instant and the subordinate's segment."""
        t, links = contact
        tt, ss = np.array([t]), np.array([seg], dtype=np.int64)
        left = left_angles(self.scenario, tt)[0]
        right = self.right_angles(tt, ss)[0]
        last = len(self.path_angles) - 1
        k = seg if 0 <= seg < last else None
        a, b = (seg, seg + 1) if k is not None else (last, last)
        return ContactDetail(t, links, (float(left[0]), float(left[1])),
                             (float(right[0]), float(right[1])), k,
                             (self.cell(a), self.cell(b)))

    def cell(self, k: int) -> tuple[int, int]:
        return (int(self.cells[k, 0]), int(self.cells[k, 1]))

    def distances(self, t: FloatArray, seg: IntArray) -> FloatArray:
        """d[k, a, b]: distance between left part a and right part b at time t[k] (3-D, with
        the heights: ``part_distances``)."""
        s = self.scenario
        left = link_rects(s.left, left_angles(s, t))                     # (K, parts, V, 2)
        right = link_rects(s.right, self.right_angles(t, seg))
        return part_distances(s, polygon_distances(left[:, :, None], right[:, None, :]))


#: The grid path's motion under its public name (read on Z3 terms by the wiring obligations).
GridMotion = _Motion


def _merge(parts: list[tuple[FloatArray, FloatArray]]) -> tuple[tuple[float, float], ...]:
    """Sorted, with touching or overlapping intervals merged."""
    if not parts:
        return ()
    t0 = np.concatenate([p[0] for p in parts])
    t1 = np.concatenate([p[1] for p in parts])
    order = np.argsort(t0, kind="stable")
    out: list[list[float]] = []
    for a, b in zip(t0[order].tolist(), t1[order].tolist()):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return tuple((a, b) for a, b in out)


# --- pure numpy -------------------------------------------------------------------------------


def part_distances(s: Scenario, planar: FloatArray) -> FloatArray:
    """The 3-D distances (..., left parts, right parts) between the parts as prisms over their
    height intervals, from their planar distances: hypot(planar, height gap) where the heights
    are apart, the planar distance where they overlap (docs/model.md §2, "Tools and heights").
    Each is Lipschitz with the same constant as the planar one (the heights do not move)."""
    gap = np.array([[height_gap(part_height(s.left, a), part_height(s.right, b))
                     for b in parts(s.right)] for a in parts(s.left)])
    if not np.any(gap > 0):
        return planar
    return np.where(gap > 0, np.hypot(planar, gap), planar)


def pose_distance(s: Scenario, left: tuple[float, float], right: tuple[float, float]) -> float:
    """The least 3-D distance between a part of the principal at joint angles ``left`` and a part
    of the subordinate at ``right`` (``part_distances`` of the planar distances); 0.0 when two
    parts whose heights overlap touch."""
    la = np.asarray(left, dtype=float)[None]
    ra = np.asarray(right, dtype=float)[None]
    planar = polygon_distances(link_rects(s.left, la)[:, :, None], link_rects(s.right, ra)[:, None, :])
    return float(part_distances(s, planar).min())


def _reach(arm: Arm) -> tuple[FloatArray, FloatArray]:
    """(R_base, R_elbow) per part, as arrays over the parts (links, then the tool)."""
    per_link = [reach(arm, link) for link in parts(arm)]
    return np.array([r[0] for r in per_link]), np.array([r[1] for r in per_link])


def interval_bound(d0: Any, d1: Any, lip: Any, length: Any) -> Any:
    """The least distance on an interval of ``length`` with samples d0, d1 at its ends and
    Lipschitz constant ``lip``: (d0 + d1 - lip length) / 2 (the module docstring). On floats,
    numpy arrays or Z3 terms (proofs/_obl_constants.py proves it a lower bound)."""
    return (d0 + d1 - lip * length) / 2.0


def pair_lipschitz(v_left: Any, v_right: Any) -> Any:
    """L_ab of a left link moving at most v_left and a right link at most v_right: their
    distance changes by at most v_left + v_right per second. On arrays or Z3 terms."""
    return v_left + v_right


def link_speeds(arm: Arm, w: FloatArray) -> FloatArray:
    """Upper bound on any part point's speed, |w1| R_base + |w2| R_elbow; w (K, 2) -> (K, parts).

    Runs on object arrays of Z3 terms as well (``reach`` does, ``abs`` is an If there)."""
    r_base, r_elbow = _reach(arm)
    w = np.abs(w)
    return w[:, 0:1] * r_base[None, :] + w[:, 1:2] * r_elbow[None, :]


def link_rects(arm: Arm, theta: FloatArray) -> FloatArray:
    """Outlines of every part at each configuration, (K, 2) -> (K, parts, V, 2): the links'
    rectangles and the tool's polygon, padded to one vertex count by repeating the last vertex
    (a zero-length edge, harmless to ``polygon_distances``)."""
    outlines = [part_points(arm, theta[:, 0], theta[:, 1], p) for p in parts(arm)]
    size = max(o.shape[-2] for o in outlines)
    padded = [o if o.shape[-2] == size else
              np.concatenate([o, np.repeat(o[..., -1:, :], size - o.shape[-2], axis=-2)], axis=-2)
              for o in outlines]
    return np.stack(padded, axis=1)


# The former private names, kept for callers that used them.
_link_speeds = link_speeds
_link_rects = link_rects
