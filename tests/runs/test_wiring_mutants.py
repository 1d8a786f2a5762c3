"""The wiring's mutants of `cfmpa selftest --code` (runs/_code_mutants.py): each is caught by
`cfmpa prove --repin` in the mutated copy through a failing obligation, control or pinned kind
(docs/model.md §7.3), run on the obligations and controls that read it."""

from __future__ import annotations

import pytest

from cfmpa.runs._code_mutants import CODE_MUTANTS, code_mutation_rows

#: Mutant -> what must catch it (the --only of its prove run: each named one must fail).
WIRING = {
    "certificate_previous_segment_speed": ["Certificate.wiring",
                                           "Control.certificate.moving_contact"],
    "trajectory_previous_row_speed": ["Certificate.wiring"],
    "monitor_gap_slice_short": ["Monitor.reference_speeds", "Control.monitor.gap_last_piece"],
    "witness_start_or_and": ["Witness.labels_sound", "Control.witness.raised_start"],
    "control_error_counted_rejected": ["Control.harness.error_is_not_a_pass"],
    "theorem_made_definitional": ["Control.accept.kinds", "Control.kinds.theorem_moved"],
    "exact_rest_layer_skipped": ["Control.exact.rest_layer_contact"],
    "exact_tool_square_corner_dropped": ["Exact.gap_formula"],
    "loader_spacing_bound_raised": ["Control.loader.spacing_above_bound"],
}


def test_the_wiring_mutants_are_registered():
    names = {m.name for m in CODE_MUTANTS}
    assert set(WIRING) <= names


@pytest.mark.slow    # a prove run in a fresh copy each: 10 s to a minute
@pytest.mark.parametrize("name", list(WIRING))
def test_each_wiring_mutant_is_caught_by_what_reads_it(name: str):
    (row,) = code_mutation_rows([name], checks=("prove",), prove_only=WIRING[name])
    assert row.caught == {"prove": True}, row.detail
    detail = row.detail["prove"]
    for ident in WIRING[name]:
        assert ident in detail, detail
