"""Which obligations and controls a ``--only`` picks (docs/model.md §6.4): read by the runner
and by the controls, so neither imports the other for it."""

from __future__ import annotations

import fnmatch
from collections.abc import Iterable

__all__ = ["selected"]


def selected(ident: str, only: Iterable[str] | None) -> bool:
    """Whether ``ident`` is picked by ``only``: an exact id, a prefix ending at a dot (``Prop8``
    picks ``Prop8.printed``), or a glob (``Thm*``). None picks everything."""
    if only is None:
        return True
    for pat in only:
        if ident == pat or ident.startswith(pat.rstrip(".") + ".") or fnmatch.fnmatchcase(ident, pat):
            return True
    return False
