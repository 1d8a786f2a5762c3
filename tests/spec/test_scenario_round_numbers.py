"""Round numbers are never refused (docs/model.md §2, §3).

A workcell file whose ranges, speeds and dt have at most three decimals, whose subordinate
ranges are whole multiples of omega dt in decimal, and whose right start and goal are angles on
that decimal grid, is read with its decimals as written, gridded on them, and planned with
exit 0. The files are written from exact decimal text (never through a float), so the reader's
``parse_float`` path is what is tested. Seeded fault: the former float reading (the grid counted
on the doubles, the float h held to omega dt with no rounding allowance) refuses the issue's
example and a workcell the strategy draws.
"""

from __future__ import annotations

import io
import tempfile
from contextlib import redirect_stderr, redirect_stdout
from fractions import Fraction
from pathlib import Path

import hypothesis.strategies as st
import pytest
from hypothesis import HealthCheck, Phase, given, settings

from cfmpa import cli
from cfmpa.errors import InputError
from cfmpa.spec import Variant, _counts, load_scenario, make_grid

#: Keeps every drawn grid small: (N + 1) m n stays below this (seconds for the whole test).
MAX_TEST_CELLS = 200_000


def dec(x: Fraction) -> str:
    """An exact decimal fraction as TOML float text (it has at most a few decimals)."""
    k = 0
    while (x * 10**k).denominator != 1:
        k += 1
    n = abs(x * 10**k).numerator
    digits = str(n).rjust(k + 1, "0")
    body = f"{digits[:-k]}.{digits[-k:]}" if k else f"{digits}.0"
    return ("-" if x < 0 else "") + body


def pair(a: Fraction, b: Fraction) -> str:
    return f"[{dec(a)}, {dec(b)}]"


def workcell_text(dt: Fraction, omega_l: tuple[Fraction, Fraction],
                  start_l: tuple[Fraction, Fraction], goal_l: tuple[Fraction, Fraction],
                  omega_r: tuple[Fraction, Fraction],
                  limits: tuple[tuple[Fraction, Fraction], tuple[Fraction, Fraction]],
                  start_r: tuple[Fraction, Fraction], goal_r: tuple[Fraction, Fraction]) -> str:
    """A scenario file; the arms' bases 1.2 m apart, so their reaches (0.68 m) overlap."""
    return "\n".join([
        'name = "round"', 'purpose = "round numbers on the decimal grid"', f"dt = {dec(dt)}",
        "[left]", "base = [0.0, 0.0]", "links = [0.35, 0.30]", "width = 0.06",
        f"omega = {pair(*omega_l)}", f"start = {pair(*start_l)}", f"goal = {pair(*goal_l)}",
        "[right]", "base = [1.2, 0.0]", "links = [0.35, 0.30]", "width = 0.06",
        f"omega = {pair(*omega_r)}",
        f"limits = [{pair(*limits[0])}, {pair(*limits[1])}]",
        f"start = {pair(*start_r)}", f"goal = {pair(*goal_r)}", ""])


def thousandths(lo: int, hi: int) -> st.SearchStrategy[Fraction]:
    return st.integers(lo, hi).map(lambda k: Fraction(k, 1000))


@st.composite
def round_workcells(draw: st.DrawFn) -> str:
    """Ranges, speeds and dt with up to three decimals; omega_q dt has at most three too (the
    decimals of omega_q and dt add up to at most three), so a range of k_q steps and the grid's
    angles lo_q + i h_q are three-decimal numbers; start and goal are drawn on that grid."""
    j = draw(st.integers(0, 3))                       # decimals of dt
    dt = Fraction(draw(st.integers(1, 10**j)), 10**j)   # at most 1 s
    omega_r = []
    for _ in range(2):
        i = draw(st.integers(0, 3 - j))               # decimals of omega_q
        top = int(Fraction(157, 50) / dt * 10**i)     # omega dt <= 3.14 rad, the loader's bound
        omega_r.append(Fraction(draw(st.integers(1, min(top, 5 * 10**i))), 10**i))
    steps = [w * dt for w in omega_r]
    lows = [draw(thousandths(-3000, 3000)) for _ in range(2)]
    ks = [draw(st.integers(1, 60)) for _ in range(2)]
    limits = tuple((lows[q], lows[q] + ks[q] * steps[q]) for q in range(2))
    start_r = tuple(lows[q] + draw(st.integers(0, ks[q])) * steps[q] for q in range(2))
    goal_r = tuple(lows[q] + draw(st.integers(0, ks[q])) * steps[q] for q in range(2))
    omega_l = (draw(thousandths(500, 3000)), draw(thousandths(500, 3000)))
    start_l = (draw(thousandths(-3000, 3000)), draw(thousandths(-3000, 3000)))
    # The principal moves for at most 20 steps, so N + 1 <= 22 and (N + 1) m n < 82,000.
    moves = [draw(st.integers(-20, 20)) for _ in range(2)]
    goal_l = tuple(start_l[q] + moves[q] * omega_l[q] * dt for q in range(2))
    return workcell_text(dt, omega_l, start_l, goal_l, (omega_r[0], omega_r[1]),
                         limits, start_r, goal_r)  # type: ignore[arg-type]


def binary_step_ok(text: str) -> bool:
    """The loader's bound omega dt <= 157/50 holds for the doubles too (else the workcell is
    not valid: the margin lemma's bound, docs/model.md §3)."""
    import tomllib
    doc = tomllib.loads(text)
    dt = doc["dt"]
    return all(Fraction(w) * Fraction(dt) <= Fraction(157, 50) and w * dt <= 3.14
               for side in ("left", "right") for w in doc[side]["omega"])


def plan_code(text: str, variant: Variant) -> tuple[int, str]:
    """`cfmpa plan FILE --variant V --contracts sampled --sample 64` in process (every
    precondition, pre.grid.h included; post.cells at 64 cells and the path): (exit code, stderr)."""
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "round.toml"
        f.write_text(text)
        err = io.StringIO()
        with redirect_stdout(io.StringIO()), redirect_stderr(err):
            code = cli.main(["plan", str(f), "--variant", variant.value, "--out",
                             str(Path(d) / "plan"), "--contracts", "sampled", "--sample", "64"])
        return code, err.getvalue()


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(round_workcells(), st.sampled_from(list(Variant)))
def test_round_number_workcells_parse_and_plan(text: str, variant: Variant) -> None:
    if not binary_step_ok(text):
        return   # refused by the margin lemma's bound, rightly (tested in test_grid_rounding)
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "round.toml"
        f.write_text(text)
        s = load_scenario(f)
        g = make_grid(s)
    assert (g.N + 1) * g.m * g.n < MAX_TEST_CELLS
    code, err = plan_code(text, variant)
    assert code == 0, err


# --- the issue's example, and the seeded fault ----------------------------------------------

EXAMPLE = workcell_text(Fraction(1, 50), (Fraction(1), Fraction(1)),
                        (Fraction(3, 10), Fraction(8, 10)), (Fraction(5, 10), Fraction(1)),
                        (Fraction(5, 2), Fraction(5, 2)),
                        ((Fraction(-2), Fraction(2)), (Fraction(-2), Fraction(2))),
                        (Fraction(0), Fraction(0)), (Fraction(3, 2), Fraction(-1)))


def old_float_reading(monkeypatch: pytest.MonkeyPatch) -> None:
    """The former reading: the grid counted on the doubles, and the float h held to omega dt
    exactly (no rounding allowance), so a point is added where the doubles round up."""
    monkeypatch.setattr(_counts, "SPEED_READING", "binary")
    monkeypatch.setattr(_counts, "SPACING_ROUNDING", 0.0)


def test_the_issues_example_plans() -> None:
    code, err = plan_code(EXAMPLE, Variant.MODIFIED)
    assert code == 0, err


def test_the_old_float_reading_refuses_the_issues_example(monkeypatch: pytest.MonkeyPatch
                                                          ) -> None:
    old_float_reading(monkeypatch)
    code, err = plan_code(EXAMPLE, Variant.MODIFIED)
    assert code == 2
    assert "right.start[0] must be a grid point" in err and "got 0.0" in err


def test_the_old_float_reading_is_caught_by_the_strategy(monkeypatch: pytest.MonkeyPatch
                                                         ) -> None:
    """Under the seeded fault some drawn workcell is refused (the loader alone: no planning)."""
    old_float_reading(monkeypatch)
    refused: list[str] = []

    @settings(max_examples=60, deadline=None, database=None, derandomize=True,
              phases=[Phase.generate])
    @given(round_workcells())
    def load(text: str) -> None:
        if not binary_step_ok(text):
            return
        with tempfile.TemporaryDirectory() as d:
            f = Path(d) / "round.toml"
            f.write_text(text)
            try:
                load_scenario(f)
            except InputError as exc:
                refused.append(str(exc))

    load()
    assert refused, "the old float reading refused none of the drawn workcells"
    assert any("must be a grid point" in r for r in refused)


# --- the text as written, not the double's shortest repr ---------------------------------------


def load_text(text: str):  # type: ignore[no-untyped-def]
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "round.toml"
        f.write_text(text)
        return load_scenario(f)


def with_dt(text: str) -> str:
    return EXAMPLE.replace("dt = 0.02\n", f"dt = {text}\n").replace(
        "start = [0.0, 0.0]", "start_cell = [0, 0]").replace("goal = [1.5, -1.0]",
                                                              "goal_cell = [1, 1]")


def test_the_decimal_is_the_files_text() -> None:
    assert "dt = 0.02\n" in EXAMPLE
    # 0.020 and 0.02 are the same number; 0.01999999999999999999 is the same double but a
    # smaller speed step as written (4 / (2.5 dt) is just above 80), so one point more.
    for text, points in (("0.02", 81), ("0.020", 81), ("2e-2", 81), ("0.01999999999999999999", 82)):
        s = load_text(with_dt(text))
        assert s.dt == 0.02
        assert make_grid(s).m == points, text
        assert s.right.omega[0] * s.dt == 2.5 * 0.02


def test_a_reader_that_drops_the_text_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    from cfmpa.spec import _scenario
    # Seeded fault: tomllib's floats kept as plain doubles (the text lost).
    monkeypatch.setattr(_scenario, "written", float)
    assert make_grid(load_text(with_dt("0.01999999999999999999"))).m == 81
