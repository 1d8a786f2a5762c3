"""The audit report (`cfmpa audit`) and the comparison campaign's presentation (`cfmpa compare`:
its table and compare.json; the campaign itself is ``cfmpa.runs.run_campaign``).

The only package of cfmpa that plots (matplotlib, in ``_figures``). ``run_prove_audit`` is
`cfmpa prove --audit`: the obligations and the report side by side, in two processes. The public
names are listed once, below (``cfmpa.lazy``), each imported on first use.
"""

from typing import TYPE_CHECKING

from ..lazy import lazy_face

if TYPE_CHECKING:     # the public names, one list: the type checker's and __all__ (cfmpa.lazy)
    # the audit report (docs/model.md §8) and `cfmpa prove --audit`
    from ._audit import build_audit as build_audit, run_audit as run_audit
    from ._prove_audit import run_prove_audit as run_prove_audit
    # `cfmpa compare`: the campaign's table and compare.json
    from ._compare import run_compare as run_compare
    # the C-space picture (docs/figures.py draws the README's)
    from ._figures import cspace_figure as cspace_figure

__getattr__, __dir__, __all__ = lazy_face(__name__, __file__)
