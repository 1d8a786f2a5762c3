"""One benchmark process: runs the items given as JSON on argv[1], prints one JSON line of results.

Each item is timed ``warmup`` times unrecorded, then ``runs`` times (or fewer if a run is slower
than the item's ``budget_s`` allows; the number is reported). Memory: the process's resident
high-water mark after the item (ru_maxrss) and its resident size before it. Run one item per
process for per-item peaks. Never imported by the package.
"""

from __future__ import annotations

import json
import math
import resource
import sys
import tempfile
import time
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def rss_mb() -> float:
    """Resident set size now (MB)."""
    pages = int(Path("/proc/self/statm").read_text().split()[1])
    return pages * resource.getpagesize() / 2**20


def peak_mb() -> float:
    """Resident high-water mark of this process so far (MB; ru_maxrss is in KB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def load(spec: dict[str, Any]):
    """The scenario of ``spec``: a bundled file, with top-level/nested overrides (a__b keys)."""
    from cfmpa.spec import parse_scenario

    doc = tomllib.loads((ROOT / spec["path"]).read_text())
    for key, value in spec.get("overrides", {}).items():
        parts = key.split("__")
        target = doc
        for p in parts[:-1]:
            target = target[p]
        target[parts[-1]] = value
    return parse_scenario(doc, check_budget=False)


def timed(fn: Callable[[], Any], runs: int, warmup: int, budget_s: float
          ) -> tuple[list[float], Any, float | None]:
    """The timed runs' seconds, the last result, and the first warm-up call's seconds (the cold
    call: the first in the process), None without a warm-up."""
    out = None
    first = None
    cold = None
    for _ in range(warmup):
        t0 = time.perf_counter()
        out = fn()
        first = time.perf_counter() - t0
        cold = first if cold is None else cold
    if first is not None and first * runs > budget_s:
        runs = max(1, math.floor(budget_s / first))
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out, cold


def item_builtdr(it: dict[str, Any]) -> tuple[Callable[[], Any], dict[str, Any]]:
    from cfmpa.impl import build_dr, build_dr_fast, load_fast_kernels, right_regions
    from cfmpa.spec import make_grid

    s = load(it["scenario"])
    g = make_grid(s)
    impl = it["impl"]
    info = {"cells": int(np.prod(g.shape)), "grid": [g.N + 1, g.m, g.n]}
    if impl == "reference":
        return (lambda: build_dr(s, it["variant"], g)), info
    if impl != "reference":
        # The kernels loaded first (from numba's cache), so the cold call (the warm-up) is the
        # first call's own work, and the warm ones are the calls after it.
        info["kernel_load_s"] = load_fast_kernels()
    if impl == "fast":
        return (lambda: build_dr_fast(s, it["variant"], g, progress=False)), info
    rr = right_regions(s, g)   # "fast_regions_given": the right arm's regions computed once
    return (lambda: build_dr_fast(s, it["variant"], g, right=rr, progress=False)), info


def item_search(it: dict[str, Any]) -> tuple[Callable[[], Any], dict[str, Any]]:
    from cfmpa.impl import build_dr_fast, search_opt_path, search_opt_path_fast

    s = load(it["scenario"])
    dr = build_dr_fast(s, it["variant"], progress=False)
    fn = search_opt_path if it["impl"] == "reference" else search_opt_path_fast
    a, b = s.right.start_cell, s.right.goal_cell
    kw = {} if it["impl"] == "reference" else {"progress": False}
    info = {"cells": int(dr.size)}

    def run():
        r = fn(dr, a, b, **kw)
        info.update(status=str(r.status), J1=r.J1, J2=r.J2)
        return r
    return run, info


def item_plan_fast(it: dict[str, Any]) -> tuple[Callable[[], Any], dict[str, Any]]:
    """plan() as `cfmpa plan` runs it (fast kernels, the item's contract mode, the certificate),
    files written; imports and the interpreter's start are outside the time."""
    from cfmpa.runs import plan, write_plan
    from cfmpa.spec import make_grid

    s = load(it["scenario"])
    g = make_grid(s)
    out = tempfile.mkdtemp(prefix="cfmpa-bench-")
    info: dict[str, Any] = {"cells": int(np.prod(g.shape)), "grid": [g.N + 1, g.m, g.n]}

    def run():
        # The default kernels (fast), as `cfmpa plan` runs them; progress is silent off a terminal.
        p = plan(s, it["variant"], contracts=it["contracts"])
        write_plan(p, out)
        info.update(status=str(p.search.status), timings_s=p.timings_s,
                    contracts=it["contracts"], violations=len(p.violations))
        return p
    return run, info


def item_builtdr_profile(it: dict[str, Any]) -> tuple[Callable[[], Any], dict[str, Any]]:
    """build_dr_fast's stages timed apart by build_dr_fast itself (its ``stages`` argument), so
    the split is of the very computation timed as "BuiltDR fast". Stage seconds of every call
    land in info["stages_s"] (warm-up included; the bench keeps the timed runs')."""
    from cfmpa.impl import _fast_builtdr as fb
    from cfmpa.impl import build_dr_fast, kernel_threads
    from cfmpa.spec import make_grid

    s = load(it["scenario"])
    g = make_grid(s)
    variant = it["variant"]
    info: dict[str, Any] = {"cells": int(np.prod(g.shape)), "grid": [g.N + 1, g.m, g.n],
                            "variant": variant, "kernel_threads": kernel_threads(),
                            "stages_s": []}

    def run():
        st: dict[str, float] = dict.fromkeys(fb.STAGES, 0.0)
        t0 = time.perf_counter()
        dr = build_dr_fast(s, variant, g, progress=False, stages=st)
        st["total"] = time.perf_counter() - t0
        info["unsure_pairs"] = int(st.pop("unsure_pairs", 0))
        info["stages_s"].append(st)
        return dr
    return run, info


def _shapely_setup(it: dict[str, Any]):
    from cfmpa.impl import build_dr_fast, left_regions, right_regions
    from cfmpa.spec import make_grid

    s = load(it["scenario"])
    g = make_grid(s)
    rr = right_regions(s, g)
    left = left_regions(s, it["variant"], g)
    ours = build_dr_fast(s, it["variant"], g, right=rr, progress=False)
    return s, g, rr, left, ours


def item_shapely_loop(it: dict[str, Any]) -> tuple[Callable[[], Any], dict[str, Any]]:
    """The obvious Python way: per cell, shapely polygons, distance <= eps; a seeded sample."""
    import shapely

    from cfmpa.spec import EPS

    s, g, rr, left, ours = _shapely_setup(it)
    rng = np.random.default_rng(it["seed"])
    sample = np.stack([rng.integers(0, g.N + 1, it["sample"]), rng.integers(0, g.m, it["sample"]),
                       rng.integers(0, g.n, it["sample"])], axis=1)
    info: dict[str, Any] = {"cells": int(np.prod(g.shape)), "sample": int(len(sample)),
                            "seed": it["seed"]}

    def run():
        got = np.empty(len(sample), dtype=np.uint8)
        for c, (k, i, j) in enumerate(sample):
            blocked = False
            for a in left.links[k]:
                pa = shapely.Polygon(a)
                for b in (rr.link1[i], rr.link2[i, j]):
                    if pa.distance(shapely.Polygon(b)) <= EPS:
                        blocked = True
            got[c] = blocked
        info["disagree_with_ours"] = int((got != ours[tuple(sample.T)]).sum())
        return got
    return run, info


def item_shapely_vector(it: dict[str, Any]) -> tuple[Callable[[], Any], dict[str, Any]]:
    """shapely 2's array API over whole layers: intersects on prepared polygons, or dwithin(eps)."""
    import shapely

    from cfmpa.spec import EPS

    s, g, rr, left, ours = _shapely_setup(it)
    stride = it.get("layer_stride", 1)
    layers = list(range(0, g.N + 1, stride))
    info: dict[str, Any] = {"cells": int(np.prod(g.shape)), "op": it["op"],
                            "layers_timed": len(layers), "layers": g.N + 1}

    def run():
        t0 = time.perf_counter()
        b1 = shapely.polygons(rr.link1)
        b2 = shapely.polygons(rr.link2.reshape(g.m * g.n, *rr.link2.shape[2:]))
        shapely.prepare(b1)
        shapely.prepare(b2)
        info["create_s"] = time.perf_counter() - t0
        bad = 0
        for k in layers:
            blocked = np.zeros((g.m, g.n), dtype=bool)
            for a in left.links[k]:
                pa = shapely.Polygon(a)
                shapely.prepare(pa)
                if it["op"] == "intersects":
                    blocked |= shapely.intersects(pa, b1)[:, None]
                    blocked |= shapely.intersects(pa, b2).reshape(g.m, g.n)
                else:
                    blocked |= shapely.dwithin(pa, b1, EPS)[:, None]
                    blocked |= shapely.dwithin(pa, b2, EPS).reshape(g.m, g.n)
            bad += int((blocked != ours[k].astype(bool)).sum())
        info["disagree_with_ours"] = bad
        return None
    return run, info


ITEMS = {"builtdr": item_builtdr, "builtdr_profile": item_builtdr_profile,
         "search": item_search, "plan_fast": item_plan_fast,
         "shapely_loop": item_shapely_loop, "shapely_vector": item_shapely_vector}


def main() -> None:
    results = []
    for it in json.loads(sys.argv[1]):
        before = rss_mb()
        fn, info = ITEMS[it["kind"]](it)
        times, _, cold = timed(fn, it["runs"], it["warmup"], it.get("budget_s", math.inf))
        results.append({"times_s": times, "cold_s": cold, "rss_before_mb": round(before, 1),
                        "peak_rss_mb": round(peak_mb(), 1), "info": info})
    print(json.dumps(results))


if __name__ == "__main__":
    main()
