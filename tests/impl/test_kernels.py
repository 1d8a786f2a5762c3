"""The kernels a run picks by name are a registry (impl/_kernels.py, docs/model.md §1.1): each
registered kernel gives the reference's D_R and path on a small workcell, the names are the
registry's in its order, and a name is resolved to its functions only when asked for. Seeded
faults: a kernel whose BuiltDR flips one cell, or whose search reports another cost, fails the
comparison every registered kernel passes; a name registered twice is refused."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import factory
from cfmpa.impl import (
    KERNELS,
    build_dr,
    build_dr_fast,
    kernel_name,
    kernels,
    search_opt_path,
    search_opt_path_fast,
)
from cfmpa.impl._kernels import REGISTRY, Kernel, registry
from cfmpa.spec import Variant, make_grid


def _differences(build: Callable[..., Any], search: Callable[..., Any]) -> list[str]:
    """How (build, search) departs from the reference on a small workcell, every variant."""
    s = factory.scenario()
    g = make_grid(s)
    out = []
    for v in Variant:
        ref, got = build_dr(s, v, g), build(s, v, g)
        if got.shape != ref.shape or not np.array_equal(got, ref):
            out.append(f"{v}: D_R differs")
            continue
        a = search_opt_path(ref, s.right.start_cell, s.right.goal_cell)
        b = search(ref, s.right.start_cell, s.right.goal_cell)
        if (a.status, a.path, a.J1, a.J2) != (b.status, b.path, b.J1, b.J2):
            out.append(f"{v}: the search differs")
    return out


def test_the_names_are_the_registry_in_order():
    assert KERNELS == tuple(REGISTRY) == ("fast", "reference", "numpy")
    assert kernels("fast") == (build_dr_fast, search_opt_path_fast)
    assert kernels() == kernels(KERNELS[0])
    assert kernels("reference") == (build_dr, search_opt_path)
    for name in KERNELS:
        assert kernel_name(*kernels(name)) == name
    assert kernel_name(build_dr, search_opt_path_fast) == "custom"
    with pytest.raises(ValueError, match="kernel='nope' is not one of fast, reference, numpy"):
        kernels("nope")


@pytest.mark.parametrize("name", KERNELS)
def test_every_registered_kernel_is_the_reference(name):
    assert _differences(*kernels(name)) == []


def test_seeded_faults_a_wrong_kernel_is_caught():
    def flipped(s, v, g, **kw):
        dr = build_dr(s, v, g, **kw).copy()
        dr[0, 0, 0] ^= 1
        return dr

    def costlier(dr, start, goal, **kw):
        r = search_opt_path(dr, start, goal, **kw)
        return dataclasses.replace(r, J1=(r.J1 or 0) + 1)

    assert _differences(flipped, search_opt_path)
    assert _differences(build_dr, costlier)


def test_a_name_registered_twice_is_refused():
    twice = (Kernel("fast", "._builtdr:build_dr", "._search:search_opt_path"),) * 2
    with pytest.raises(ValueError, match="kernel 'fast' is registered twice"):
        registry(twice)


def test_a_cold_stand_in_must_be_registered():
    assert REGISTRY["fast"].cold == "numpy"            # what "fast" runs while it compiles
    lone = (Kernel("fast", "._builtdr:build_dr", "._search:search_opt_path", cold="numpy"),)
    with pytest.raises(ValueError, match="runs 'numpy' while cold, which is not registered"):
        registry(lone)


def test_the_registry_imports_no_kernel():
    # The parser lists KERNELS; the fast kernels (numba) load only when a kernel is asked for.
    probe = ("import sys\nfrom cfmpa.impl import KERNELS\nassert KERNELS\n"
             "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=60, check=True).stdout
    assert out.strip() == "False"
