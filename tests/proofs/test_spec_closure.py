"""The translation checks' pinned text covers the spec modules their checkers rest on, not
only the functions they name (docs/model.md §6.4): the every-cell postcondition lives in
spec/_builtdr_post.py, which the check reaches through dr_cell_failures."""

from __future__ import annotations

import inspect

from cfmpa.proofs import BUNDLED_DIR, _obligation
from cfmpa.proofs._obl_scenario import _query, _translation
from cfmpa.proofs._obligation import spec_closure
from cfmpa.spec import dr_cell_failures


def _content() -> str:
    return _query(BUNDLED_DIR / "default.toml", _translation, "translation_modified").content


def test_the_closure_reaches_the_modules_the_checkers_call_into():
    names = spec_closure(dr_cell_failures)
    for m in ("_triples", "_builtdr_post", "_regions", "_kinematics", "_grid"):
        assert f"cfmpa.spec.{m}" in names
    assert not any(n.startswith("cfmpa.impl") for n in names)     # the kernels are judged


def test_an_edit_to_a_called_helper_changes_the_translation_checks_text(monkeypatch):
    before = _content()
    assert "# module cfmpa.spec._builtdr_post sha256 " in before
    real = inspect.getsource

    def edited(obj):                         # the postcondition's module, one line longer
        text = real(obj)
        return text + "\n# edited\n" if getattr(obj, "__name__", "") == (
            "cfmpa.spec._builtdr_post") else text

    _obligation._module_facts.cache_clear()
    monkeypatch.setattr(_obligation.inspect, "getsource", edited)
    try:
        after = _content()
    finally:
        _obligation._module_facts.cache_clear()
    assert after != before
    changed = set(after.splitlines()) - set(before.splitlines())
    assert len(changed) == 1 and "cfmpa.spec._builtdr_post" in changed.pop()
