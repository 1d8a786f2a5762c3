"""witness.start (found path) is the spec's own test on terms (proofs/_obl_witness.py's
labels.base runs spec.start_label_breaks): proved as written, refuted with its or made and, and
the checker rejects a raised start label at witness.start."""

from __future__ import annotations

import numpy as np
import pytest
import z3

from cfmpa.proofs import _controls as C
from cfmpa.proofs import _obl_witness as OW
from cfmpa.spec import MOVES, Witness, check_witness, start_label_breaks
from z3answer import answer


def _base():
    return next(vc for vc in OW.witness_vcs("labels") if vc.name == "labels.base")


def test_labels_base_reads_the_checker_s_start_test():
    vc = _base()
    assert answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]) == z3.unsat
    assert any("start_label_breaks" in n for n, _ in vc.hypotheses)


def test_the_start_test_with_and_is_refuted(monkeypatch):
    monkeypatch.setattr(OW, "start_label_breaks", lambda j1, j2: (j1 != 0) & (j2 != 0))
    vc = _base()
    assert answer([h for _, h in vc.hypotheses] + [z3.Not(vc.goal)]) == z3.sat


@pytest.mark.parametrize("label", [(0, 0), (0, 1), (1, 0), (3, 4)])
def test_the_start_test_on_numbers_and_terms_agree(label):
    j1, j2 = z3.Ints("j1 j2")
    term = z3.simplify(z3.substitute(start_label_breaks(j1, j2), (j1, z3.IntVal(label[0])),
                                     (j2, z3.IntVal(label[1]))))
    got = bool(start_label_breaks(np.uint16(label[0]), np.uint16(label[1])))
    assert z3.is_true(term) == got == (label != (0, 0))


@pytest.mark.parametrize("which", ["j1", "j2", "none"])
def test_the_checker_rejects_a_start_not_labelled_zero(which):
    c = C._case()
    at = (0, MOVES.index((0, 0)), c.start[0], c.start[1])
    j1, j2 = c.best.witness.j1.copy(), c.best.witness.j2.copy()
    if which == "none":
        j1[at] = j2[at] = np.iinfo(j1.dtype).max
    else:
        (j1 if which == "j1" else j2)[at] = 1
    failures = check_witness(c.dr, c.start, c.goal, c.best, Witness.of_labels(j1, j2))
    assert failures and failures[0].condition == "witness.start"
