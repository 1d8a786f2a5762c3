"""`cfmpa plan` with the fast kernels, as a fresh process: what the CLI does once wired to them.

Usage: _plan_fast.py SCENARIO VARIANT OUT CONTRACTS. The same steps as ``cfmpa plan`` (load,
plan with contracts and certificate, write dr.npy and plan.json), imports included in the time.
Never imported by the package.
"""

from __future__ import annotations

import sys

from cfmpa.impl import build_dr_fast, search_opt_path_fast
from cfmpa.proofs._plan import plan, write_plan
from cfmpa.spec import load_scenario


def main(scenario: str, variant: str, out: str, contracts: str) -> int:
    s = load_scenario(scenario)
    p = plan(s, variant, contracts=contracts, build=build_dr_fast, search=search_opt_path_fast)
    write_plan(p, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:5]))
