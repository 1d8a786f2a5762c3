"""The audit report (`cfmpa audit`) and the comparison campaign's presentation (`cfmpa compare`:
its table and compare.json; the campaign itself is ``cfmpa.runs.run_campaign``).

The only package of cfmpa that plots (matplotlib, in ``_figures``).
"""

from ._audit import (DEFAULT_COMPARE_N, AuditResult, build_audit, render_html, run_audit,
                     write_report)
from ._compare import campaign_json, format_campaign, run_compare
from ._figures import Figure, cspace_figure

__all__ = [
    "AuditResult", "DEFAULT_COMPARE_N", "Figure", "build_audit", "campaign_json", "cspace_figure",
    "format_campaign", "render_html", "run_audit", "run_compare", "write_report",
]
