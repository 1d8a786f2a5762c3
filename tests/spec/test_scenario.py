"""The scenario loader refuses every bad input before any work, naming the field and the value."""

from __future__ import annotations

import math
import string
from fractions import Fraction
from pathlib import Path

import hypothesis.strategies as st
import pytest
from hypothesis import given, settings

import factory
from cfmpa.errors import InputError
from cfmpa.spec import exact_n, exact_tf, load_scenario, make_grid, parse_scenario

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
    ({"dt": 0.0005}, "dt", "memory budget"),
])
def test_bad_input_is_refused_naming_field_and_value(changes, field, words):
    err = refused(**changes)
    assert err.field == field
    assert words in str(err)
    assert err.exit_code == 2


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
    monkeypatch.setenv("CFMPA_MAX_CELLS", str(10**9))
    s = parse_scenario(factory.doc(dt=0.005))
    assert s.cells > 60_000_000 // 100  # accepted now, and really large
    monkeypatch.setenv("CFMPA_MAX_CELLS", "lots")
    with pytest.raises(InputError, match="CFMPA_MAX_CELLS"):
        parse_scenario(factory.doc())


def test_file_errors_carry_file_and_line(tmp_path):
    bad = tmp_path / "bad.toml"
    text = Path(factory.__file__).parent.parent.joinpath("scenarios", "default.toml").read_text()
    bad.write_text(text.replace("dt = 0.02", "dt = -1.0"))
    err = pytest.raises(InputError, load_scenario, bad).value
    line = text.splitlines().index("dt = 0.02") + 1
    assert err.render() == f"{bad}:{line}: error: dt must be > 0, got -1.0"
    broken = tmp_path / "broken.toml"
    broken.write_text('name = "x\n')
    assert pytest.raises(InputError, load_scenario, broken).value.line == 1
    assert "cannot be read" in str(pytest.raises(InputError, load_scenario, tmp_path / "no.toml").value)


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


_scalars = st.one_of(st.none(), st.booleans(), st.integers(-5, 5), st.text(string.printable, max_size=4),
                     st.floats(allow_nan=True, allow_infinity=True), st.just(math.nan))
_values = st.recursive(_scalars, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                        st.dictionaries(st.text(max_size=6), inner,
                                                                        max_size=3)), max_leaves=8)
_paths = st.sampled_from(["name", "purpose", "dt", "left", "right", "left__base", "left__links",
                          "left__width", "left__omega", "left__start", "left__goal", "right__base",
                          "right__links", "right__width", "right__omega", "right__limits",
                          "right__start_cell", "right__goal_cell", "right__start", "extra",
                          "left__extra"])


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(_paths, _values, min_size=1, max_size=4))
def test_malformed_documents_raise_only_input_errors(changes):
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
    try:
        parse_scenario(d)
    except InputError as err:
        assert err.field and err.exit_code == 2
