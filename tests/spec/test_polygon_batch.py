"""The batch-last polygon distance (spec/_polygon.py ``_distances``, docs/model.md §7) is
``_distances_reference``, the method as first written, bit for bit: on random convex, degenerate
(a point, a segment, repeated and collinear vertices), touching and overlapping polygons, and
through the certificate (clear, contact and undecided verdicts; the default, gripper and levels
workcells). Seeded faults: a copy of the module with one operation changed disagrees."""

from __future__ import annotations

import inspect
import json
import types

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cfmpa.scenarios import BUNDLED_DIR
from cfmpa.spec import Trajectory, _polygon, certificate_json, certify_trajectory, load_scenario

coord = st.floats(min_value=-2.0, max_value=2.0, allow_nan=False, allow_infinity=False)
#: Small integers too, so that touching, collinear and repeated vertices are common.
grid_coord = st.integers(min_value=-3, max_value=3).map(float)


def _bits(x: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=np.float64).view(np.int64)


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull vertices in boundary order (monotone chain); a point or a segment as is."""
    pts = sorted({(float(x), float(y)) for x, y in points})
    if len(pts) <= 2:
        return np.array(pts, dtype=float)

    def half(ps: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in ps:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=float)


def _pad(p: np.ndarray, v: int) -> np.ndarray:
    return np.concatenate([p, np.repeat(p[-1:], v - len(p), axis=0)]) if len(p) < v else p


@st.composite
def batches(draw: st.DrawFn) -> tuple[np.ndarray, np.ndarray]:
    """Two batches of polygons padded to one vertex count each (up to 9 vertices: numpy sums
    eight and more terms pairwise), some reversed, some raw (degenerate) point lists."""
    n = draw(st.integers(1, 6))
    va, vb = draw(st.integers(1, 9)), draw(st.integers(1, 9))
    out = []
    for v in (va, vb):
        polys = []
        for _ in range(n):
            c = draw(st.sampled_from([coord, grid_coord]))
            pts = np.array(draw(st.lists(st.tuples(c, c), min_size=1, max_size=v)), dtype=float)
            p = pts if draw(st.booleans()) and len(pts) <= 2 else _hull(pts)
            if draw(st.booleans()):
                p = p[::-1]
            polys.append(_pad(p[:v], v))
        out.append(np.stack(polys))
    return out[0], out[1]


@settings(max_examples=150, deadline=None)
@given(batches())
def test_batch_last_distances_are_the_reference_bit_for_bit(ab):
    a, b = ab
    got = _polygon._distances(a, b)
    assert np.array_equal(_bits(got), _bits(_polygon._distances_reference(a, b)))
    # broadcast: every a against every b
    cross = _polygon._distances(a[:, None], b[None, :])
    assert cross.shape == (len(a), len(b))
    assert np.array_equal(_bits(cross), _bits(_polygon._distances_reference(a[:, None],
                                                                            b[None, :])))


@pytest.mark.parametrize("lead_a,lead_b", [((0, 2, 1), (0, 1, 2)), ((), ()), ((3,), ()),
                                            ((2, 1), (1, 0))])
def test_empty_and_single_batches(lead_a, lead_b):
    rng = np.random.default_rng(3)
    a, b = rng.uniform(-1, 1, (*lead_a, 4, 2)), rng.uniform(-1, 1, (*lead_b, 5, 2))
    got = _polygon._distances(a, b)
    want = _polygon._distances_reference(a, b)
    assert got.shape == want.shape and np.array_equal(_bits(got), _bits(want))


def _agree(fn) -> bool:
    """``fn`` gives the reference's distances on a fixed set of overlapping, touching, apart
    and degenerate pairs (both orders)."""
    rng = np.random.default_rng(7)
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    bar = np.array([[-1, -0.1], [1, -0.1], [1, 0.1], [-1, 0.1]])
    cases = [(sq, sq + [2.0, 0.5]), (sq, sq + [1.0, 0.0]), (sq, sq + [0.5, 0.5]),
             (sq, sq * 0.2 + 0.4), (sq, np.array([[0.5, -1.0], [0.5, 2.0], [0.5, 2.0],
                                                   [0.5, 2.0]])),
             (sq, np.array([[-1.0, 0.5], [2.0, 0.6], [2.0, 0.6], [2.0, 0.6]])),
             (sq, np.array([[3.0, 3.0]] * 4)), (sq, sq[::-1] + [0.3, 1.7]),
             (sq, sq + [1.5, 1.5]),                   # corner to corner
             (bar, bar[:, ::-1])]                     # a plus: edges cross, no vertex in
    for _ in range(40):
        c = rng.uniform(-1, 2, 2)
        th = rng.uniform(0, 2 * np.pi)
        rot = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        cases.append((sq, (sq - 0.5) @ rot.T * rng.uniform(0.2, 1.5) + c))
    a = np.stack([x for x, _ in cases] + [y for _, y in cases])
    b = np.stack([y for _, y in cases] + [x for x, _ in cases])
    # the whole batch (a zero-length edge in it) and each pair alone (most have none)
    return all(np.array_equal(_bits(fn(x, y)), _bits(_polygon._distances_reference(x, y)))
               for x, y in [(a, b), *zip(a[:, None], b[:, None])])


def _planted(old: str, new: str):
    """``_distances`` of a copy of spec/_polygon.py with ``old`` replaced by ``new``."""
    src = inspect.getsource(_polygon)
    assert src.count(old) == 1, old
    mod = types.ModuleType("planted_polygon")
    mod.__dict__["__name__"] = "cfmpa.spec.planted_polygon"
    mod.__dict__["__package__"] = "cfmpa.spec"
    exec(compile(src.replace(old, new), "planted_polygon", "exec"), mod.__dict__)
    return mod._distances


@pytest.mark.parametrize("old,new", [
    ("side -= eyb * relx", "side += eyb * relx"),               # a wrong cross product
    ("np.clip(t, 0.0, 1.0, out=t)", "np.clip(t, 0.0, 2.0, out=t)"),   # past the edge's end
    ("meet = (np.any(_straddles(side_ab)", "meet = (0 * np.any(_straddles(side_ab)"),  # no cross
    ("orient_a = np.broadcast_to(_orientation(a)", "orient_a = np.broadcast_to(-_orientation(a)"),
    ("| _contains(side_ab, orient_a) | _contains(side_ba, orient_b))",
     "| _contains(side_ab, orient_a))"),                        # b inside a is missed
    ("np.subtract(x[0], x[-1], out=out[-1])", "np.subtract(x[-1], x[0], out=out[-1])"),
])
def test_seeded_fault_a_changed_operation_disagrees(old, new):
    assert _agree(_polygon._distances)
    assert not _agree(_planted(old, new))


# --- through the certificate ------------------------------------------------------------------


def _random_trajectory(rng: np.random.Generator, rows: int, spread: float) -> Trajectory:
    """Rows every 0.05-0.3 s about the arms' start, the right arm ``spread`` rad about a pose
    near the left (contact likely for a large spread)."""
    t = np.cumsum(rng.uniform(0.05, 0.3, rows))
    left = np.array([1.68, -2.44]) + rng.uniform(-spread, spread, (rows, 2))
    right = np.array([2.2, 1.2]) + rng.uniform(-spread, spread, (rows, 2))
    return Trajectory(t, np.column_stack([left, right]) % (2 * np.pi))


@pytest.mark.parametrize("name", ["default", "gripper", "levels"])
def test_certificates_are_the_reference_bit_for_bit(name, monkeypatch):
    s = load_scenario(BUNDLED_DIR / f"{name}.toml")
    rng = np.random.default_rng({"default": 1, "gripper": 2, "levels": 3}[name])
    verdicts = set()
    for k in range(24):
        traj = _random_trajectory(rng, int(rng.integers(1, 12)), [0.3, 1.0, 2.5][k % 3])
        depth = int(rng.integers(0, 6))
        docs = []
        for fn in (_polygon._distances, _polygon._distances_reference):
            monkeypatch.setattr(_polygon, "_distances", fn)
            cert = certify_trajectory(s, traj, max_depth=depth)
            docs.append(json.dumps(certificate_json(cert)))
        assert docs[0] == docs[1]
        doc = json.loads(docs[0])
        verdicts.add("contact" if doc["contact"] else "undecided" if doc["undecided"] else
                     "clear")
    assert verdicts == {"clear", "contact", "undecided"}
