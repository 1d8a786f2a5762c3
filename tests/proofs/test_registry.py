"""One record per obligation: each declared once (``Obligation(...)`` in a collector of
``_runner.COLLECTORS``), the expected verdicts, kinds, summaries and fixed ids being views of
the declarations; proofs/obligations.lock stays the independent pin (docs/model.md §10)."""

from __future__ import annotations

import importlib.util
import textwrap
from pathlib import Path

import pytest

from cfmpa.proofs import _runner, _summaries
from cfmpa.proofs._obligation import Verdict
from cfmpa.proofs._pins import LOCK, load_lock, pin_key

_THROWAWAY = '''
from cfmpa.proofs._obligation import CheckOutcome, CheckQuery, Method, Obligation, Verdict


def throwaway_obligations():
    return [Obligation("Throwaway.one", "Throwaway", "nowhere", "1 = 1.", Method.DATA,
                       Verdict.PROVED, lambda: CheckQuery(lambda: CheckOutcome(True, "ok"), "1"),
                       definitional="a definition restated",
                       summary="A throwaway obligation declared once, in one file.")]
'''


def _throwaway(tmp_path: Path):
    """A collector module written to a file and imported: one declaration, nothing else."""
    path = tmp_path / "throwaway_obl.py"
    path.write_text(textwrap.dedent(_THROWAWAY))
    spec = importlib.util.spec_from_file_location("throwaway_obl", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.throwaway_obligations


def test_the_views_are_the_declarations():
    d = _runner.declared()
    obs = [o for c in _runner.COLLECTORS for o in c()]
    assert _runner.EXPECTED_VERDICTS == d.expected == {o.id: o.expected for o in obs}
    assert _runner.DEFINITIONAL == d.definitional == {o.id: o.definitional for o in obs
                                                       if o.definitional}
    assert _runner.FIXED_IDS == tuple(o.id for o in obs)      # the lock pins no other id
    assert all(_runner.kind_of(o.id) == o.kind for o in obs)
    assert all(_runner.kind_and_why(o.id) == (o.kind, o.definitional) for o in obs)
    assert all(_summaries.SUMMARIES[o.id] == o.summary for o in obs)
    assert len(_runner.DEFINITIONAL) == 9 and len(_runner.EXPECTED_VERDICTS) == 63
    # The per-scenario checks' sentences are patterns, read off their declarations.
    assert _summaries.obligation_summary("Scenario.gripper.containment").startswith(
        "gripper: the tight swept region lies inside")


def test_one_declaration_in_one_file_is_in_every_view(tmp_path: Path, monkeypatch):
    collector = _throwaway(tmp_path)
    d = _runner.declared((*_runner.COLLECTORS, collector))
    assert d.expected["Throwaway.one"] is Verdict.PROVED
    assert d.definitional["Throwaway.one"] == "a definition restated"
    assert d.summaries["Throwaway.one"] == "A throwaway obligation declared once, in one file."
    assert "Throwaway.one" in _runner.fixed_ids(d.expected, load_lock(LOCK))
    assert _summaries.summary_problems(["Throwaway.one"], d.summaries) == []
    # The run collects it from the registry, with nothing else edited.
    monkeypatch.setattr(_runner, "COLLECTORS", (*_runner.COLLECTORS, collector))
    assert [o.id for o in _runner.collect_obligations("/nonexistent", ["Throwaway"])] == [
        "Throwaway.one"]
    # Not in the module's views (they were computed without it): the lock does not pin it,
    # so a run of it says "not pinned" until --repin.
    assert "Throwaway.one" not in _runner.EXPECTED_VERDICTS
    assert pin_key("Throwaway.one") not in load_lock(LOCK)


def test_a_declaration_that_disappears_is_still_expected():
    # Seeded fault: one declaration dropped from the code. The lock still pins its id, so the
    # fixed ids still hold it and a run that does not produce it misses it.
    lock = load_lock(LOCK)
    kept = [i for i in _runner.EXPECTED_VERDICTS if i != "Prop8.printed"]
    ids = _runner.fixed_ids(kept, lock)
    assert ids[-1] == "Prop8.printed" and set(ids) == set(_runner.EXPECTED_VERDICTS)
    missing, unexpected, _ = _runner.compare_ids(kept, ids)
    assert missing == ("Prop8.printed",) and unexpected == ()
    # Without the lock's ids the drop would go unnoticed: the check is the lock's.
    assert _runner.compare_ids(kept, _runner.fixed_ids(kept, {}))[0] == ()


def test_a_drifted_expectation_is_caught_by_the_lock():
    # Seeded fault: a declaration's expected verdict changed; the lock pins the old one.
    lock = load_lock(LOCK)
    assert lock["Prop8.printed"]["expected"] == _runner.EXPECTED_VERDICTS["Prop8.printed"].value
    assert all(lock[i]["expected"] == v.value for i, v in _runner.EXPECTED_VERDICTS.items())
    assert all(lock[i]["kind"] == _runner.kind_of(i) for i in _runner.EXPECTED_VERDICTS)


def test_an_id_declared_twice_is_refused(tmp_path: Path):
    collector = _throwaway(tmp_path)
    with pytest.raises(ValueError, match="Throwaway.one"):
        _runner.declared((collector, collector))


def test_summaries_module_holds_no_table_of_its_own():
    # Every sentence comes from a declaration: the module's source names no obligation id.
    src = Path(_summaries.__file__).read_text()
    assert '"Prop8.printed"' not in src and "Scenario.*.containment" not in src
