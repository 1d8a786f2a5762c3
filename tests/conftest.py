"""Shared test set-up: tests/ is on sys.path, so test modules can `import factory`."""

import os

from hypothesis import settings

# CI runs one fixed set of examples (CFMPA_HYPOTHESIS=ci, set by .ci/run), so a red run there is
# a property of the commit, not of the draw; elsewhere each run draws new examples.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CFMPA_HYPOTHESIS") == "ci":
    settings.load_profile("ci")


def pytest_sessionstart(session):
    """Compile the fast kernels first where numba's cache is cold (in parallel, docs/model.md
    §7.5), so their one line on stderr goes to the terminal, not into the first test that calls
    a kernel and reads its stderr. With a warm cache this prints nothing."""
    from cfmpa.impl import ensure_compiled

    ensure_compiled()
