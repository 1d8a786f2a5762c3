"""The scenario loader refuses every bad input before any work, naming the field and the value."""

from __future__ import annotations

import math
import string
from fractions import Fraction
from pathlib import Path

import hypothesis.strategies as st
import numpy as np
import pytest
import shapely
from hypothesis import given, settings

import factory
from cfmpa import cli
from cfmpa.errors import MISSING, InputError
from cfmpa.spec import (
    Variant,
    exact_n,
    exact_tf,
    left_angles,
    left_box,
    load_scenario,
    make_grid,
    parse_scenario,
    right_box,
)
from cfmpa.spec._kinematics import link_corners
from cfmpa.spec._regions import SNAP, right_region_polygons
from cfmpa.spec._scenario import DEFAULT_MAX_CELLS

SCENARIOS = sorted(Path(__file__).resolve().parents[2].joinpath("scenarios").glob("*.toml"))


def refused(**changes: object) -> InputError:
    with pytest.raises(InputError) as info:
        parse_scenario(factory.doc(**changes), check_budget=True)
    return info.value


@pytest.mark.parametrize("changes, field, words", [
    ({"dt": None}, "dt", "is required"),
    ({"left__omega": None}, "left.omega", "is required"),
    ({"colour": "red"}, "colour", "not a known key"),
    ({"right__speed": 3}, "right.speed", "not a known key"),
    ({"dt": "fast"}, "dt", "must be a number"),
    ({"dt": True}, "dt", "must be a number"),
    ({"left__links": [0.3]}, "left.links", "list of 2"),
    ({"left__links": [0.3, 0.2, 0.1]}, "left.links", "list of 2"),
    ({"dt": math.nan}, "dt", "must be finite"),
    ({"left__start": [math.inf, 0.0]}, "left.start[0]", "must be finite"),
    ({"dt": 0.0}, "dt", "must be > 0"),
    ({"dt": -0.1}, "dt", "must be > 0"),
    ({"right__omega": [1.0, -1.0]}, "right.omega[1]", "must be > 0"),
    ({"left__width": 0.0}, "left.width", "must be > 0"),
    ({"left__links": [0.35, 0.0]}, "left.links[1]", "must be > 0"),
    ({"right__limits": [[1.0, 0.0], [0.0, 1.0]]}, "right.limits[0]", "lo < hi"),
    ({"right__limits": [[0.0, 1.0]]}, "right.limits", "list of 2"),
    ({"right__start_cell": [3, 99]}, "right.start_cell[1]", "grid index"),
    ({"right__goal_cell": [-1, 0]}, "right.goal_cell[0]", "grid index"),
    ({"right__goal_cell": [1.5, 0]}, "right.goal_cell[0]", "integer"),
    ({"right__goal_cell": None, "right__goal": [0.1, 0.0]}, "right.goal[0]", "grid point"),
    ({"right__goal_cell": None, "right__goal": [7.0, 0.0]}, "right.goal[0]", "within the limits"),
    ({"right__goal_cell": None}, "right.goal_cell", "exactly one of"),
    ({"name": ""}, "name", "non-empty"),
    ({"dt": 0.0005}, "grid", "memory budget"),
    # Extreme magnitudes: refused by name, never an OverflowError or an unsound grid.
    ({"right__limits": [[-1e308, 1e308], [0.0, 1.0]]}, "right.limits[0]", "finite span"),
    ({"right__limits": [[-1e308, 1e308], [0.0, 6.3]], "right__goal_cell": None,
      "right__goal": [0.0, 0.0]}, "right.limits[0]", "finite span"),
    ({"right__limits": [[0.0, 6.3], [-1e300, 1e300]]}, "right.limits[1][0]", "within [-1000"),
    ({"right__omega": [1e-300, 1.0]}, "grid", "no budget may exceed 2**53"),
    ({"left__width": 1e160}, "left.width", "<= 100 m"),
    ({"right__width": 1e308}, "right.width", "<= 100 m"),
    ({"left__links": [1e200, 0.3]}, "left.links[0]", "<= 100 m"),
    ({"right__links": [0.35, 5e-324], "right__goal_cell": [0, 0, 1]}, "right.goal_cell",
     "list of 2"),  # a tiny link is fine: the next field is the first refused
    ({"left__base": [0.0, -1001.0]}, "left.base[1]", "within [-1000, 1000] m"),
    ({"right__base": [1e308, 0.0]}, "right.base[0]", "within [-1000, 1000] m"),
    ({"left__start": [1e6, 0.0]}, "left.start[0]", "within [-1000, 1000] rad"),
    ({"left__omega": [13.0, 1.0]}, "left.omega[0]", "must be <= 3.14"),
    ({"right__omega": [1.0, 1e308]}, "right.omega[1]", "must be <= 3.14"),
    ({"dt": 3.5}, "left.omega[0]", "must be <= 3.14"),
    ({"dt": 10**400}, "dt", "must be finite"),
])
def test_bad_input_is_refused_naming_field_and_value(changes, field, words):
    err = refused(**changes)
    assert err.field == field
    assert words in str(err)
    assert err.exit_code == 2
    # The message shows the offending value, and it is the value the document held.
    if err.value is MISSING:
        assert "got" not in str(err)
        return
    assert str(err).endswith(f", got {err.value!r}")
    if field == "grid":
        assert err.value.startswith("N=")   # its sizes; numbers checked in the next test
    elif changes == {"dt": 10**400}:
        assert err.value == "1.000e+400"    # a 400-digit integer, shortened
    else:
        held = _parts(list(changes.values()))
        # Either the field's own value was changed, or (omega * dt) the message shows the change.
        assert err.value in held or any(f"= {v!r}" in str(err) for v in held)


def _parts(v: object) -> list[object]:
    """v and, for a list, every item at every depth."""
    return [v] + [y for x in v for y in _parts(x)] if isinstance(v, list) else [v]


def test_budget_message_names_the_grid_and_caps_its_numbers():
    err = refused(dt=0.0005)
    text = str(err)
    assert "N=2801, m=12568, n=12568" in text
    assert "442588856448 cells" in text and f"{DEFAULT_MAX_CELLS} cells" in text
    assert "CFMPA_MAX_CELLS" in text and "largest factor is m" in text
    huge = str(refused(right__omega=[1e-300, 1.0]))
    assert "m=2.513e+301" in huge and "cells, over" in huge
    assert max(len(w) for w in huge.replace(",", " ").split()) < 40  # no 300-digit numbers
    # The factor blamed follows the grid: a long motion makes N + 1 the largest.
    slow = str(refused(left__omega=[1e-6, 1e-6]))
    assert "largest factor is N + 1 (from dt, left.omega" in slow


def test_off_grid_angle_names_the_nearest_grid_points():
    err = refused(right__goal_cell=None, right__goal=[0.1, 0.0])
    text = str(err)
    assert "index 0 = 0.0" in text and "index 1 = 0.24166" in text


def test_angles_on_grid_points_are_accepted_as_cells():
    g = make_grid(factory.scenario())
    s = parse_scenario(factory.doc(right__goal_cell=None,
                                   right__goal=[5 * g.h[0] + 5e-10, 7 * g.h[1]]))
    assert s.right.goal_cell == (5, 7)


def test_budget_can_be_raised_by_environment(monkeypatch):
    monkeypatch.setenv("CFMPA_MAX_CELLS", str(10**6))
    with pytest.raises(InputError, match="over the memory budget of"):
        parse_scenario(factory.doc(dt=0.005))
    monkeypatch.setenv("CFMPA_MAX_CELLS", str(10**9))
    s = parse_scenario(factory.doc(dt=0.005))
    assert s.cells > 10**6  # over the lowered budget, accepted once it is raised
    monkeypatch.setenv("CFMPA_MAX_CELLS", "lots")
    with pytest.raises(InputError, match="CFMPA_MAX_CELLS"):
        parse_scenario(factory.doc())
    # A value of any length is echoed cut short (cfmpa.files.echo), in one short line.
    monkeypatch.setenv("CFMPA_MAX_CELLS", "9" * 100_000 + "x")
    with pytest.raises(InputError, match="CFMPA_MAX_CELLS") as exc:
        parse_scenario(factory.doc())
    assert len(str(exc.value)) < 300 and "\n" not in str(exc.value)


def test_file_errors_carry_file_and_line(tmp_path):
    bad = tmp_path / "bad.toml"
    text = Path(factory.__file__).parent.parent.joinpath("scenarios", "default.toml").read_text()
    bad.write_text(text.replace("dt = 0.02", "dt = -1.0"))
    err = pytest.raises(InputError, load_scenario, bad).value
    line = text.splitlines().index("dt = 0.02") + 1
    assert err.render() == f"{bad}:{line}: error: dt must be > 0, got -1.0"
    right = text.splitlines().index("[right]                   # subordinate")
    nested = tmp_path / "nested.toml"
    nested.write_text(text.replace("width = 0.06\nomega = [1.0, 1.0]\nlimits",
                                   "width = -2.0\nomega = [1.0, 1.0]\nlimits"))
    err = pytest.raises(InputError, load_scenario, nested).value
    assert err.line == right + 4 and err.field == "right.width"
    broken = tmp_path / "broken.toml"
    broken.write_text('name = "x\n')
    assert pytest.raises(InputError, load_scenario, broken).value.line == 1
    assert "cannot be read" in str(pytest.raises(InputError, load_scenario, tmp_path / "no.toml").value)


def test_cli_reports_file_and_line_of_a_nested_field_under_a_commented_header(tmp_path, capsys):
    # Every bundled scenario's table headers carry a comment (`[left]   # principal`).
    text = SCENARIOS[0].read_text()
    lines = text.splitlines()
    header = next(n for n, line in enumerate(lines) if line.startswith("[left]"))
    assert "#" in lines[header]
    at = next(n for n in range(header + 1, len(lines)) if lines[n].startswith("omega = "))
    lines[at] = "omega = [1.0, -3.5]"
    bad = tmp_path / "bad.toml"
    bad.write_text("\n".join(lines) + "\n")
    code = cli.main(["dr", str(bad), "--variant", "modified", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    assert err == f"{bad}:{at + 1}: error: left.omega[1] must be > 0, got -3.5\n"
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bundled_scenarios_load_and_round_safely(path):
    s = load_scenario(path)
    g = make_grid(s)
    assert s.purpose.strip()
    assert Fraction(g.N) * Fraction(s.dt) >= exact_tf(s)
    assert g.N == exact_n(s)
    for q, points in enumerate((g.m, g.n)):
        lo, hi = s.right.limits[q]
        assert (Fraction(hi) - Fraction(lo)) / (points - 1) <= \
            Fraction(s.right.omega[q]) * Fraction(s.dt)


def test_grid_formulas_on_the_tiny_scenario():
    g = make_grid(factory.scenario())
    # Tf = 1.4 s (joint 2: 1.4 rad at 1 rad/s); 2.2 - 0.8 rounds above 1.4 in floats, so N = 6.
    assert (g.N, g.m, g.n) == (6, 27, 27)
    assert g.shape == (7, 27, 27)
    assert g.h[0] <= 1.0 * 0.25


_extreme = st.sampled_from([1e308, -1e308, 1.7976931348623157e308, 5e-324, -5e-324, 0.0, -0.0,
                            1e160, 1e-300, 3.15, 10**400, 2**63])
_floats = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.just(math.nan), _extreme)
_scalars = st.one_of(st.none(), st.booleans(), st.integers(-5, 5), st.text(string.printable, max_size=4),
                     _floats)
# Well-formed pairs with extreme entries, so the fuzz reaches the arithmetic, not only the types.
_pairs = st.lists(st.one_of(_floats, st.floats(-10, 10)), min_size=2, max_size=2)
_values = st.one_of(
    _pairs, st.lists(_pairs, min_size=2, max_size=2),
    st.recursive(_scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                   st.dictionaries(st.text(max_size=6), inner,
                                                                   max_size=3)), max_leaves=8))
_paths = st.sampled_from(["name", "purpose", "dt", "left", "right", "left__base", "left__links",
                          "left__width", "left__omega", "left__start", "left__goal", "right__base",
                          "right__links", "right__width", "right__omega", "right__limits",
                          "right__start_cell", "right__goal_cell", "right__start", "extra",
                          "left__extra"])


def _apply(changes: dict[str, object]) -> dict[str, object]:
    d = factory.doc()
    for key, value in changes.items():
        parts = key.split("__")
        target = d
        for p in parts[:-1]:
            target = target[p] if isinstance(target.get(p), dict) else target.setdefault(p, {})
            if not isinstance(target, dict):
                break
        else:
            target[parts[-1]] = value
    return d


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(_paths, _values, min_size=1, max_size=4))
def test_malformed_documents_raise_only_input_errors(changes):
    try:
        parse_scenario(_apply(changes))
    except InputError as err:
        assert err.field and err.exit_code == 2
        assert f"got {err.value!r}" in str(err) or "is required" in str(err)


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(["dt", "left__width", "right__width", "left__links", "right__links",
                        "left__base", "right__base", "left__omega", "right__omega", "left__start",
                        "left__goal", "right__limits"]),
       st.lists(st.one_of(_extreme, st.floats(-1e3, 1e3)), min_size=4, max_size=4))
def test_extreme_floats_are_refused_by_name_or_give_a_sane_grid(key, xs):
    value: object = xs[0] if key.endswith(("dt", "width")) else xs[:2]
    if key == "right__limits":
        value = [xs[:2], xs[2:]]
    d = _apply({key: value, "right__start_cell": [0, 0], "right__goal_cell": [0, 0]})
    try:
        s = parse_scenario(d)
    except InputError as err:
        assert err.field and err.exit_code == 2
        assert f"got {err.value!r}" in str(err)
        return
    g = make_grid(s)   # an accepted scenario has a grid within the budget, every step finite
    assert (g.N + 1) * g.m * g.n <= DEFAULT_MAX_CELLS
    assert all(math.isfinite(x) and x >= 0 for x in g.h)
    assert all(s.left.omega[q] * s.dt <= 3.14 and s.right.omega[q] * s.dt <= 3.14
               for q in range(2))


# ---- The principal's PTP motion and the variants' boxes (docs/model.md §2, §4) ----

_angle = st.floats(-3.2, 3.2)


@st.composite
def _motions(draw):
    """Random left-arm motions, goal below start in either joint included (s = -1)."""
    start = [draw(_angle), draw(_angle)]
    goal = [start[q] + draw(st.one_of(st.just(0.0), st.floats(-1.6, 1.6))) for q in range(2)]
    omega = [draw(st.floats(0.3, 2.5)), draw(st.floats(0.3, 2.5))]
    dt = draw(st.sampled_from([0.02, 0.1, 0.125, 0.25, 0.4]))
    return factory.scenario(dt=dt, left__start=start, left__goal=goal, left__omega=omega,
                            right__start_cell=[0, 0], right__goal_cell=[0, 0])


def _within(x: np.ndarray, box: tuple[float, float], tol: float) -> float:
    return bool((x >= box[0] - tol).all() and (x <= box[1] + tol).all())


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # t / Tf, Tf ~ 1e-16
@settings(max_examples=60, deadline=None)
@given(_motions())
def test_each_layers_box_holds_the_motion_and_the_variants_nest(s):
    g = make_grid(s)
    assert Fraction(g.N) * Fraction(s.dt) >= exact_tf(s)
    # Original and modified boxes are a + (-1, 0, 1) omega dt: rounding may leave the motion a few
    # ulps outside, which the regions' snap slack SNAP * omega_q dt covers; allow 1% of it.
    tol = [SNAP * s.left.omega[q] * s.dt / 100 for q in range(2)]
    for k in range(g.N):
        t = np.linspace(k * s.dt, (k + 1) * s.dt, 65)
        theta = left_angles(s, t)
        boxes = {v: left_box(s, v, k) for v in Variant}
        for q in range(2):
            assert _within(theta[:, q], boxes[Variant.TIGHT][q], 0.0)
            for v in (Variant.MODIFIED, Variant.ORIGINAL):
                assert _within(theta[:, q], boxes[v][q], tol[q])
            assert _within(np.array(boxes[Variant.TIGHT][q]), boxes[Variant.MODIFIED][q], tol[q])
            assert _within(np.array(boxes[Variant.MODIFIED][q]), boxes[Variant.ORIGINAL][q], 0.0)
            # The modified box lies on the side the joint moves to (s = -1 when goal < start).
            lo, hi = boxes[Variant.MODIFIED][q]
            a = float(left_angles(s, k * s.dt)[q])
            assert (lo == a) if s.left.goal[q] > s.left.start[q] else (hi == a)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
@settings(max_examples=150, deadline=None)
@given(_motions())
def test_every_joint_arrives_exactly_at_tf(s):
    tf = exact_tf(s)
    start, goal = np.array(s.left.start), np.array(s.left.goal)
    assert tuple(left_angles(s, float(tf))) == s.left.goal
    assert tuple(left_angles(s, float(tf) + 1.0)) == s.left.goal      # and rests there
    assert tuple(left_angles(s, 0.0)) == s.left.start
    moving = np.abs(goal - start) > 1e-6    # an ulp-sized move may round onto the goal early
    if moving.any():
        before = left_angles(s, float(tf) * (1 - 1e-6))
        assert (before[moving] != goal[moving]).all()      # no joint arrives early
        # Synchronised: every joint has covered the same fraction of its way at any time.
        mid = left_angles(s, float(tf) / 3)
        # Compared as angles, within a few ulps of them: as a fraction of a tiny move the same
        # rounding looks large (a 1e-5 rad move gives 1e-11).
        want = start + (goal - start) / 3
        ulps = np.spacing(np.maximum(np.abs(start), np.abs(goal)))
        assert (np.abs(mid - want)[moving] <= 8 * ulps[moving]).all()
    # At least one joint runs at its speed limit, none faster.
    speeds = [abs(Fraction(s.left.goal[q]) - Fraction(s.left.start[q])) / tf if tf else 0
              for q in range(2)]
    assert all(v <= Fraction(s.left.omega[q]) for q, v in enumerate(speeds))
    assert tf == 0 or any(v == Fraction(s.left.omega[q]) for q, v in enumerate(speeds))


@settings(max_examples=40, deadline=None)
@given(_motions(), st.integers(0, 10**6), st.floats(0, 1), st.floats(0, 1))
def test_right_box_is_the_cell_swept_by_its_region(s, seed, f1, f2):
    # right_box(cell) = [t_i -+ h1] x [t_j -+ h2]; the spec's S_RArm[i][j] holds the arm there.
    g = make_grid(s)
    i, j = seed % g.m, (seed // g.m) % g.n
    box = right_box(g, (i, j))
    for q, idx in enumerate((i, j)):
        t = float(g.angle(q, idx))
        assert box[q] == (t - g.h[q], t + g.h[q])
    theta = (box[0][0] + f1 * (box[0][1] - box[0][0]), box[1][0] + f2 * (box[1][1] - box[1][0]))
    r1, r2 = right_region_polygons(s, g, np.array([i]), np.array([j]))
    for link, region in enumerate((r1[0], r2[0])):
        rect = shapely.Polygon(link_corners(s.right, theta, link))
        assert shapely.difference(rect, region).area <= 1e-15
