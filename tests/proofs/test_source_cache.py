"""The sources the proofs hash and read on terms, read once a process: the cached reading is
inspect's, function by function (not by name: the proof modules hold several ``_query``)."""

from __future__ import annotations

import inspect
import textwrap

from cfmpa.proofs import _obl_builtdr, _obl_monitor, _obl_scenario, _obl_tools, _onterms
from cfmpa.proofs._obligation import check_source, source_of
from cfmpa.spec import heights_overlap

SAME_NAMED = (_obl_scenario._query, _obl_builtdr._query, _obl_monitor._query)


def test_source_of_is_inspects_reading_per_function():
    for fn in SAME_NAMED + (_obl_tools.tool_region_query, _onterms._Reader.__init__):
        assert source_of(fn) == inspect.getsource(fn).rstrip()
    assert len({source_of(fn) for fn in SAME_NAMED}) == len(SAME_NAMED)
    assert check_source(*SAME_NAMED) == "\n".join(
        inspect.getsource(f).rstrip() for f in SAME_NAMED)


def test_a_cache_keyed_by_name_is_caught():
    """The seeded fault: keyed by __name__, the modules' ``_query`` functions share a source,
    which the per-function check above rejects."""
    by_name: dict[str, str] = {}

    def wrong(fn):
        return by_name.setdefault(fn.__name__, inspect.getsource(fn).rstrip())

    assert wrong(SAME_NAMED[0]) == source_of(SAME_NAMED[0])
    assert any(wrong(fn) != source_of(fn) for fn in SAME_NAMED[1:])


def test_dedented_source_is_read_once_and_right():
    _onterms._dedented_source.cache_clear()
    text = _onterms._dedented_source(heights_overlap)
    assert text == textwrap.dedent(inspect.getsource(heights_overlap))
    assert _onterms._dedented_source(heights_overlap) is text
