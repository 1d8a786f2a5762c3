"""The audit report (`cfmpa audit`) and the comparison campaign's presentation (`cfmpa compare`:
its table and compare.json; the campaign itself is ``cfmpa.runs.run_campaign``).

The only package of cfmpa that plots (matplotlib, in ``_figures``). ``run_prove_audit`` is
`cfmpa prove --audit`: the obligations and the report side by side, in two processes.
"""

from ._audit import (DEFAULT_COMPARE_N, AuditResult, build_audit, render_html, run_audit,
                     write_report)
from ._compare import campaign_json, format_campaign, run_compare
from ._figures import Figure, cspace_figure
from ._prove_audit import run_prove_audit

__all__ = [
    "AuditResult", "DEFAULT_COMPARE_N", "Figure", "build_audit", "campaign_json", "cspace_figure",
    "format_campaign", "render_html", "run_audit", "run_compare", "run_prove_audit",
    "write_report",
]
