"""The while program of Theorems 1 and 3 is extracted from the loop-form BuiltDR: its shape, the
subset's refusals, and planted changes of the loop form that change the program and fail the
proof."""

from __future__ import annotations

import inspect

import pytest
import z3

import factory
from cfmpa.impl import builtdr_loop_nest
from cfmpa.proofs._extract import ExtractionError, extract
from cfmpa.proofs._obl_builtdr import PLANTED_BUGS, _query, builtdr_source
from cfmpa.proofs._while import For, Seq
from cfmpa.spec.z3defs import Z3Dims

SOURCE = inspect.getsource(builtdr_loop_nest)
VARIANTS = ("original", "modified", "tight")
LABELS = ("A.k", "B.i", "B.j", "C.k", "C.i", "C.j", "D.i", "D.j")
N, m, n = z3.Ints("N m n")
SMALL = (N == 2, m == 2, n == 2)


def _extract(source: str = SOURCE, variant: str = "original", **kw):
    d = Z3Dims.named()
    return extract(variant=variant, pre=d.sane(), dims=d, source=source, **kw)


def _answer(vc, pinned: bool = True) -> z3.CheckSatResult:
    # Quantified queries: an unknown is retried under other seeds, and never counts as sat.
    answer = z3.unknown
    for seed in range(3):
        s = z3.Solver()
        s.set("timeout", 20_000)
        s.set("random_seed", seed)
        s.add([h for _, h in vc.hypotheses])
        s.add(z3.Not(vc.goal))
        if pinned:
            s.add(*SMALL)
        answer = s.check()
        if answer != z3.unknown:
            return answer
    return answer


def _fingerprint(q) -> tuple[tuple[str, str], ...]:
    return tuple((vc.name, vc.goal.sexpr()) for vc in q.vcs)


def _loops(cmd) -> list[str]:
    if isinstance(cmd, Seq):
        return [x for c in cmd.cmds for x in _loops(c)]
    if isinstance(cmd, For):
        return [cmd.label, *_loops(cmd.body)]
    return []


def test_the_program_has_the_hand_written_shape():
    ex = _extract()
    assert ex.labels == LABELS
    assert _loops(ex.program) == list(LABELS)
    assert [p.label for p in ex.phases] == ["A", "B", "C", "D"]
    assert [str(p.array) for p in ex.phases] == ["SL", "SR", "P", "P"]


@pytest.mark.parametrize("variant", VARIANTS)
def test_vc_counts_are_unchanged(variant):
    assert len(_query(variant, "correctness").vcs) == 9       # main + one per loop
    assert len(_query(variant, "termination").vcs) == 25      # main + three per loop


@pytest.mark.parametrize("variant", VARIANTS)
def test_the_correct_loop_form_is_proved(variant):
    for vc in _query(variant, "correctness").vcs:
        assert _answer(vc, pinned=False) == z3.unsat, vc.name


def test_the_variant_is_decided_at_extraction():
    tight = _fingerprint(_query("tight", "correctness"))
    original = _fingerprint(_query("original", "correctness"))
    assert any("regionRest_tight" in g for _, g in tight)
    assert not any("regionRest_tight" in g for _, g in original)
    assert not any("regionL_original" in g for _, g in tight)


def test_the_stored_value_reads_through_to_the_regions():
    # The rest layer's fact names regionL(N - 1), not SL[N - 1]: reads are replaced.
    (rest,) = [p for p in _extract().phases[3:]]
    assert "regionL_original" in rest.spec.sexpr() and "SL" not in rest.spec.sexpr()


CASES = [(bug, v) for bug, (vs, _) in PLANTED_BUGS.items() for v in vs]


@pytest.mark.parametrize("bug,variant", CASES, ids=[f"{b}-{v}" for b, v in CASES])
def test_a_planted_change_changes_the_program_and_fails_the_proof(bug, variant):
    assert builtdr_source(bug) != SOURCE
    correct = _query(variant, "correctness")
    buggy = _query(variant, "correctness", bug)
    assert _fingerprint(buggy) != _fingerprint(correct)
    answers = {vc.name: _answer(vc) for vc in buggy.vcs}
    # The invariants come from the buggy program, so its loops are consistent; the triple fails.
    assert answers[f"BuiltDR.{variant}.main"] == z3.sat, answers
    for vc in correct.vcs:
        assert _answer(vc) == z3.unsat, vc.name


def test_a_weak_invariant_fails_preservation():
    weak = {vc.name: vc for vc in _query("original", "correctness", "weak_invariant").vcs}
    assert _answer(weak["C.i.preserve"]) == z3.sat
    assert _answer(weak["BuiltDR.original.main"]) == z3.unsat


def test_a_source_parameter_is_what_gets_proved():
    src = factory.edited(SOURCE, ("P[N, i, j] = 1", "P[N, i, j] = 0"))
    q = _query("modified", "correctness", source=src)
    assert _answer({vc.name: vc for vc in q.vcs}["BuiltDR.modified.main"]) == z3.sat


REFUSED = [
    ("while", ("    for k in range(0, N):\n        SL[k] = region_left(k)\n",
               "    k = 0\n    while k < N:\n        SL[k] = region_left(k)\n"), "Assign"),
    ("while_loop", ("    for k in range(0, N):\n        SL[k] = region_left(k)\n",
                    "    while N:\n        SL[0] = region_left(0)\n"), "While"),
    ("one_argument_range", ("for k in range(0, N):\n        SL", "for k in range(N):\n        SL"),
     "range with 1 argument"),
    ("non_helper_call", ("SL[k] = region_left(k)", "SL[k] = print(k)"), "not a helper"),
    ("plain_assignment", ("        SL[k] = region_left(k)\n",
                          "        SL[k] = region_left(k)\n        x = 1\n"), "more than one"),
    ("extra_statement", ("        SL[k] = region_left(k)\n",
                         "        SL[k] = region_left(k)\n        SL[k] = region_left(k)\n"),
     "more than one"),
    ("multiplication", ("SL[N - 1]", "SL[N * 1]"), "Mult"),
    ("transposed_store", ("SR[i, j] = region_right(i, j)", "SR[j, i] = region_right(i, j)"),
     "nesting order"),
    ("unknown_name", ("P[k, i, j] = 1", "P[k, i, j] = one"), "unknown name"),
    ("return", ("                P[N, i, j] = 0\n",
                "                P[N, i, j] = 0\n    return P\n"),
     "Return"),
    ("for_else", ("        SL[k] = region_left(k)\n",
                  "        SL[k] = region_left(k)\n    else:\n        pass\n"), "for-else"),
    ("decorator", ("def builtdr_loop_nest", "@staticmethod\ndef builtdr_loop_nest"), "decorators"),
    ("if_without_else", ("                    P[k, i, j] = 1\n                else:\n"
                         "                    P[k, i, j] = 0\n",
                         "                    P[k, i, j] = 1\n"),
     "both branches"),
    ("read_before_written", ("inter(SL[k], SR[i, j])", "inter(SL[k], P[k, i, j])"), "before"),
    ("bound_uses_counter", ("for j in range(0, n):\n            SR",
                            "for j in range(0, i):\n            SR"),
     "counter 'i'"),
    ("conditional_on_data", ("if rule.rest_at_goal", "if N"), "rule.<field>"),
    ("conditional_on_the_name", ("if rule.rest_at_goal", 'if variant == "tight"'),
     "rule.<field>"),
    ("conditional_on_a_non_boolean_field", ("if rule.rest_at_goal", "if rule.words"),
     "not a Boolean field"),
    ("conditional_on_no_field", ("if rule.rest_at_goal", "if rule.at_rest"), "rule.at_rest"),
    ("store_into_name", ("SL[k] = region_left(k)", "Q[k] = region_left(k)"), "not an array"),
    ("counter_in_index_expr", ("SL[k] = region_left(k)", "SL[k + 1] = region_left(k)"),
     "computed from the counter"),
    ("unknown_parameter", ("inter: Callable", "spare: int, inter: Callable"), "not a known name"),
]


@pytest.mark.parametrize("edit,fragment", [(e, f) for _, e, f in REFUSED],
                         ids=[r[0] for r in REFUSED])
def test_outside_the_subset_is_refused_naming_the_line(edit, fragment):
    src = factory.edited(SOURCE, edit)
    with pytest.raises(ExtractionError, match=r"^line \d+: ") as err:
        _extract(src)
    assert fragment in str(err.value)


def test_the_error_quotes_the_offending_line():
    src = factory.edited(SOURCE, ("SL[k] = region_left(k)", "SL[k] = print(k)"))
    with pytest.raises(ExtractionError) as err:
        _extract(src)
    line = int(str(err.value).split(":")[0].split()[1])
    assert "print(k)" in src.splitlines()[line - 1] and "print(k)" in str(err.value)


def test_a_smaller_nest_extracts_and_proves_its_own_fact():
    src = ("def f(N, SL, region_left):\n"
           "    for k in range(0, N):\n"
           "        SL[k] = region_left(k)\n")
    ex = _extract(src)
    assert ex.labels == ("A.k",)
    (phase,) = ex.phases
    from cfmpa.proofs._while import verification_conditions
    d = Z3Dims.named()
    for vc in verification_conditions("small", d.sane(), ex.program, phase.fact()):
        assert _answer(vc, pinned=False) == z3.unsat, vc.name
