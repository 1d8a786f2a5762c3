"""A VC's own Z3 solver (``VC.z3_tactic``, docs/model.md §6.1): the proof check of the VCs that
carry one runs on it, still unsat under the obligation's resource limit, their vacuity check
still sat, their statement (the lock's hash) unchanged, and the saved query replays it.

The resource counts are deterministic for one Z3 build: each bound below is at most half what
Z3's default solver used on that VC, so a check that ignores the tactic runs over it (planted
below: ``_solver`` with the tactic dropped).
"""

from __future__ import annotations

import dataclasses
import functools

import pytest
import z3

from cfmpa.proofs import _limits, _obligation, _registry
from cfmpa.proofs._obligation import (
    VC,
    Obligation,
    Verdict,
    Z3Query,
    _check_texts,
    _run_z3,
    check_command,
    render_query,
    standard_smtlib,
)
from cfmpa.proofs._pins import load_lock

#: Per obligation, its VCs that carry a tactic, and the most resource units each proof check
#: may use with it (Z3's default solver: convex_norm 11.6 M, the walks 2.5 M, labels.step
#: 2.2 M, the tool's reach 1.35 M, Prop8's exists 1.9 M; measured with the tactic: 0.74 M,
#: 0.19 M, 0.32 M, 24 k, 19 k).
TACTIC_VCS = {
    "Prop8.path_exists": {"exists": 200_000},
    "Lemma.sweep_margin": {"convex_norm": 2_000_000},
    "Witness.labels_sound": {"labels.walk": 1_000_000, "labels.step": 1_000_000},
    "Witness.reachable_sound": {"reachable.walk": 1_000_000},
    "Safety.tool_region": {"tool_reach": 300_000},
    "Certificate.lipschitz": {"tool_reach_frame": 300_000},
}


class _NoCvc5:
    """A cvc5 pool that replays nothing (these tests are about Z3's checks)."""

    def submit(self, *args, **kwargs):
        return None


@functools.cache
def _obligation_and_query(ident: str) -> tuple[Obligation, Z3Query]:
    ob = next(o for c in _registry.COLLECTORS for o in c() if o.id == ident)
    q = ob.build()
    assert isinstance(q, Z3Query)
    return ob, q


def _tactic_part(ident: str) -> tuple[Obligation, Z3Query]:
    """The obligation and its query cut to the VCs that carry a tactic (no smoke tests)."""
    ob, q = _obligation_and_query(ident)
    return ob, dataclasses.replace(q, vcs=tuple(v for v in q.vcs if v.z3_tactic), smoke=())


def _without_tactic(vc: VC) -> VC:
    return dataclasses.replace(vc, z3_tactic=None, z3_tactic_params=())


@pytest.mark.parametrize("ident", sorted(TACTIC_VCS))
def test_the_vcs_with_a_tactic_are_those_measured(ident):
    _, q = _tactic_part(ident)
    assert [v.name for v in q.vcs] == list(TACTIC_VCS[ident])


@pytest.mark.parametrize("ident", sorted(TACTIC_VCS))
def test_proof_check_runs_on_the_tactic_unsat_and_vacuity_still_sat(ident):
    ob, q = _tactic_part(ident)
    fields, _, _ = _run_z3(ob, q, _NoCvc5(), {})
    assert fields["verdict"] is Verdict.PROVED, fields["reason"]
    for r in fields["vcs"]:
        assert (r.vacuity, r.answer) == ("sat", "unsat"), r.name
        # The count recorded is the tactic's: far below the default solver's.
        assert 0 < r.rlimit_count[1] <= TACTIC_VCS[ident][r.name], (r.name, r.rlimit_count)
        assert r.rlimit_count[1] * 10 <= fields["rlimit"], "Z3_RLIMITS no longer 10x the count"


def test_a_solver_that_ignores_the_tactic_is_caught(monkeypatch):
    """The bound's calibration, with the fault planted here: ``_solver`` dropping the tactic.
    convex_norm's proof check then runs on Z3's default solver, over TACTIC_VCS's bound (and,
    under a limit of 3 M, ends unknown), so the test above goes red on that fault."""
    real = _obligation._solver

    def ignoring(*args, tactic=None, tactic_params=(), **kwargs):
        return real(*args, **kwargs)

    ob, q = _tactic_part("Lemma.sweep_margin")
    monkeypatch.setattr(_obligation, "_solver", ignoring)
    monkeypatch.setitem(_limits.Z3_RLIMITS, ob.id, 3_000_000)
    fields, _, _ = _run_z3(ob, q, _NoCvc5(), {})
    assert fields["verdict"] is Verdict.UNKNOWN
    assert fields["vcs"][0].rlimit_count[1] >= 3_000_000 > TACTIC_VCS[ob.id]["convex_norm"]


@pytest.mark.parametrize("ident", sorted(TACTIC_VCS))
def test_the_statement_and_its_pin_are_unchanged(ident):
    """The tactic is how the check runs, not what it states: the standard SMT-LIB's hash is
    the VC's without it, and the one proofs/obligations.lock pins."""
    _, q = _tactic_part(ident)
    pins = load_lock()[ident]["vcs"]
    for vc in q.vcs:
        sha = standard_smtlib(vc)[1]
        assert sha == standard_smtlib(_without_tactic(vc))[1] == pins[vc.name], vc.name


def test_check_command_spells_the_tactic_and_its_parameters():
    x = z3.Real("x")
    vc = VC("v", (("x > 0", x > 0),), x >= 0)
    assert check_command(vc) == "(check-sat)"
    assert (check_command(dataclasses.replace(vc, z3_tactic="qfnra-nlsat"))
            == "(check-sat-using qfnra-nlsat)")
    both = dataclasses.replace(vc, z3_tactic="smt",
                               z3_tactic_params=(("ematching", False), ("random_seed", 3)))
    assert (check_command(both)
            == "(check-sat-using (using-params smt :ematching false :random_seed 3))")
    # Dropping a premise for a negative test gives Z3's default solver back.
    assert both.without("x > 0").z3_tactic is None


def _blocks(text: str) -> dict[str, str]:
    """The saved query's checks by their comment's head ("VC name: proof ...")."""
    out = {}
    for block in text.split("\n\n")[1:]:
        head = block.split("\n", 1)[0]
        out[head.split(";")[1].strip()] = block
    return out


def test_the_saved_query_replays_the_proof_check_as_run():
    """render_query writes the tactic in the proof check's block, not in the vacuity check's;
    Z3 replaying that block's text answers unsat with the tactic's count, and with plain
    (check-sat) runs over the bound: the text is the check that ran."""
    ob, q = _tactic_part("Lemma.sweep_margin")
    blocks = _blocks(render_query(ob, q, _check_texts(q)))
    proof = blocks["VC convex_norm: proof (expect unsat)"]
    vacuity = blocks["VC convex_norm: vacuity (expect sat)"]
    using = "(check-sat-using (using-params qfnra-nlsat :reorder false))"
    assert using in proof and "(check-sat-using" not in vacuity

    def replay(text: str) -> tuple[str, int]:
        ctx = z3.Context()     # held: the call borrows its pointer
        out = z3.Z3_eval_smtlib2_string(ctx.ref(), text + "\n(get-info :rlimit)")
        answer, count = out.split("\n", 1)
        return answer.strip(), int(count.strip().strip("()").split()[1])

    answer, count = replay(proof)
    assert answer == "unsat" and count <= TACTIC_VCS[ob.id]["convex_norm"]
    bound = f"(set-option :rlimit {TACTIC_VCS[ob.id]['convex_norm']})"
    plain = "\n".join(bound if line.startswith("(set-option :rlimit") else line
                      for line in proof.replace(using, "(check-sat)").splitlines())
    assert replay(plain)[0] == "unknown"
