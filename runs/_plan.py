"""`cfmpa plan`: BuiltDR, searchoptpath (under contracts) and the certificate, as docs/model.md §9's files.

Output is deterministic: the same scenario bytes, variant and version give byte-identical JSON
apart from the ``timings_s`` object. A found path whose certificate is not clear (a contact, or
an interval left undecided) is a violation in every contract mode, ``off`` included: the
certificate is the safety result, not a contract. Files are written even when there are
violations (they are the evidence); `cfmpa plan` then exits 1.
"""

from __future__ import annotations

import functools
import hashlib
import math
import platform
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO, TypeVar, cast

import numpy as np
import numpy.typing as npt

from .. import __version__
from ..errors import ContractViolation, InputError
from ..files import dumps_json, write_atomic_with, write_bytes_atomic
from ..impl import kernel_name, load_fast_kernels, search_opt_path
from ..spec import (
    Certificate,
    Grid,
    Scenario,
    SearchResult,
    SearchStatus,
    Variant,
    certificate_json,
    certify,
    contact_links_text,
    executed_trajectory,
    make_grid,
    require_clear,
    save_npz,
    theorem_scope,
    tolerance_rad,
    trajectory_csv,
)
from ._contracts import (
    Builder,
    BuiltDRCheck,
    Mode,
    Searcher,
    Settings,
    TripleRun,
    checked_search,
    contracts_json,
    violation_json,
)

if TYPE_CHECKING:     # the exact re-decision loads python-flint: only plan() needs it
    from ..spec import ExactGaps
    from ._drdask import BuiltStore, EngineOptions

R = TypeVar("R")

__all__ = ["CERTIFICATE", "TRAJ_CSV", "PlanResult", "clearance_line", "plan", "plan_json",
           "run_dr", "run_plan", "write_plan", "versions"]


@dataclass(frozen=True)
class PlanResult:
    """One planning run: the grid, D_R, the search's answer, the certificate, the contracts' record
    (plan.json's ``contracts``) and the timings; ``runs`` are the contract checks as values."""

    scenario: Scenario
    variant: Variant
    grid: Grid
    #: D_R: the array, or with dr.zarr (the fast kernel) the store read a layer at a time
    #: (``ZarrDr.layers``).
    dr: npt.NDArray[np.uint8]
    search: SearchResult
    certificate: Certificate | None
    contracts: dict[str, Any] | None
    timings_s: dict[str, float] = field(default_factory=dict)
    runs: tuple[TripleRun, ...] = ()
    kernel: str = "custom"
    settings: Settings = field(default_factory=Settings)
    #: The path's (layer, cell) pairs re-decided in ball arithmetic (None without a path).
    exact: ExactGaps | None = None

    @property
    def checked(self) -> int:
        """Items the contracts examined (cells, path steps, conditions)."""
        return sum(r.checked for r in self.runs)

    @property
    def free_fraction(self) -> float:
        """1 - the mean of D_R; for D_R read from its store a layer at a time (`cfmpa plan
        --workers | --scheduler`), from its count of blocked cells: the same float, as the
        mean of a 0/1 array is its exact count over the cells."""
        if isinstance(self.dr, np.ndarray):
            return 1.0 - float(self.dr.mean())
        return 1.0 - self.dr.blocked_cells() / math.prod(self.dr.shape)

    @property
    def violations(self) -> list[ContractViolation]:
        """Every violation recorded (empty unless the run was asked not to stop at one)."""
        out = [v for r in self.runs for v in r.violations()]
        cert = self.certificate
        if cert is not None and not cert.clear:
            out.append(_certificate_violation(cert))
        if self.exact is not None and not self.exact.ok:
            out.append(_exact_violation(self.exact))
        return out


def versions() -> dict[str, str]:
    """Versions that can change an answer: the tool, Python, numpy, shapely, Z3."""
    import shapely

    return {"cfmpa": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "shapely": shapely.__version__, "z3": z3_version()}


def z3_version() -> str:
    """``z3.get_version_string()`` (major.minor.build) without importing Z3, which `cfmpa plan`
    does not otherwise need (tests/test_startup.py): the z3-solver distribution's version is
    major.minor.build.revision. Imports Z3 only when that metadata is missing."""
    from importlib import metadata

    try:
        return ".".join(metadata.version("z3-solver").split(".")[:3])
    except metadata.PackageNotFoundError:
        import z3
        return str(z3.get_version_string())


def plan(s: Scenario, variant: Variant | str, *, contracts: Mode | str = "off", seed: int = 0,
         sample: int | None = None, stop: bool = True, grid: Grid | None = None,
         build: Builder | None = None, search: Searcher | None = None,
         kernel: str | None = None, witness: bool = False,
         overlap: bool | None = None) -> PlanResult:
    """Plan the subordinate's path for ``variant`` with BuiltDR and searchoptpath under contracts.

    ``contracts`` is off (this function's default; `cfmpa plan` defaults to full), sampled
    (``sample`` random cells, ``seed``) or full (see _contracts).
    In every mode, off included, a certificate that is not clear (a contact, or an interval left
    undecided) is a violation. A violation raises ContractViolation; with ``stop=False``
    postcondition and certificate violations are recorded in ``contracts`` and the run goes on
    (a failed precondition always stops it). ``grid``, ``build`` and ``search`` replace the
    scenario's grid and the kernels (None: the fast ones, bit-identical to the reference and
    tested against it; imported only then, so that a run on the numpy kernels while the fast
    ones compile never imports numba, docs/model.md §7.5): for the reference itself, another
    implementation, or a seeded fault. ``kernel`` names
    them in plan.json ("fast", "reference"; by default told from ``build`` and ``search``, and
    "custom" for anything else). With the fast kernels, the first run in a process first calls
    them on a tiny input, so that timings_s.kernel_load holds numba's compile or cache-load time
    and build_dr / search hold the work alone (kernel_load is 0.0 once they are loaded).
    ``witness`` (and ``full`` contracts) ask the search for its certificate
    (``SearchResult.witness``, docs/model.md §11; a search that makes none gets the fast
    search's), which ``write_plan`` can write and ``full`` verifies; timings_s.search then
    includes making it. The result keeps it only when ``witness`` asked for it.
    ``overlap`` (docs/model.md §7.5): BuiltDR's postcondition check in a forked worker process
    beside the search and what follows it (True), in the serial order (False), or where it can
    help (None: ``overlap_helps``); the same result, record and violation either way.
    """
    v = Variant(variant)
    settings = Settings.of(contracts, seed, sample)
    g = grid or make_grid(s)
    enforce = settings.mode is not Mode.OFF
    if build is None or search is None:
        from ..impl import build_dr_fast, search_opt_path_fast
        build = build_dr_fast if build is None else build
        search = search_opt_path_fast if search is None else search
    kernel = kernel or kernel_name(build, search)
    if (witness or settings.mode is Mode.FULL) and _makes_witness(search):
        # (Any: the two take with_witness, which Searcher's signature does not name.)
        search = functools.partial(cast(Any, search), with_witness=True)
    t: dict[str, float] = {}
    if kernel == "fast":
        t["kernel_load"] = _load_fast_kernels()
    built = BuiltDRCheck(s, v, g, settings, build=_timed(build, t, "build_dr"), stop=stop,
                         overlap=overlap)
    dr = built.dr
    if enforce:
        t["contracts_builtdr"] = built.seconds    # its place in timings_s; set once joined
    with built:          # a postcondition check in its worker process is joined here (§7.5)
        t0 = time.perf_counter()
        result, search_runs = checked_search(s, v, g, dr, settings, established=built.established,
                                             search=_timed(search, t, "search"), stop=stop)
        if enforce:
            t["contracts_search"] = time.perf_counter() - t0 - t["search"]
        if witness and result.witness is None:
            from ..impl import search_opt_path_fast
            made = search_opt_path_fast(dr, s.right.start_cell, s.right.goal_cell,
                                        with_witness=True)
            result = replace(result, witness=made.witness)
        elif not witness and result.witness is not None:
            result.witness.close()                    # its temporary files, if spilled
            result = replace(result, witness=None)    # checked; not kept (N + 1 grids large)
        cert = None
        exact = None
        if result.status is SearchStatus.FOUND:
            t0 = time.perf_counter()
            cert = certify(s, g, result.path)
            t["certificate"] = time.perf_counter() - t0
            if stop:
                require_clear(cert, name=CERTIFICATE)
            t0 = time.perf_counter()
            from ..spec import exact_path_gaps  # python-flint, for plan only (not `cfmpa dr`)
            exact = exact_path_gaps(s, v, g, result.path)
            t["exact_gaps"] = time.perf_counter() - t0
            if stop and not exact.ok:
                raise _exact_violation(exact)
    runs = built.runs + built.settled(search_runs)
    if enforce:
        t["contracts_builtdr"] = built.seconds
        if built.overlapped:
            t["contracts_builtdr_overlapped"] = built.overlapped
    record = contracts_json(settings, runs,
                            _certificate_violation(cert) if cert and not cert.clear else None,
                            certificate_checked=True)
    if exact is not None and not exact.ok:
        # Before the certificate's own violation, which stays the last (the safety result).
        at = len(record["violations"]) - (1 if cert is not None and not cert.clear else 0)
        record["violations"].insert(at, violation_json(_exact_violation(exact)))
    return PlanResult(scenario=s, variant=v, grid=g, dr=dr, search=result, certificate=cert,
                      contracts=record, timings_s=t, runs=tuple(runs), kernel=kernel,
                      settings=settings, exact=exact)


def _makes_witness(search: Searcher) -> bool:
    """Whether ``search`` is the reference or the fast search (they take ``with_witness``). The
    fast one is looked for only if its module is loaded (a function of a module never imported
    cannot be ``search``), so the check imports no numba."""
    if search is search_opt_path:
        return True
    fast = sys.modules.get(search_opt_path.__module__.rsplit(".", 1)[0] + "._fast_search")
    return fast is not None and search is getattr(fast, "search_opt_path_fast", None)


def _load_fast_kernels() -> float:
    """Seconds spent loading the fast kernels in this process by this call (0.0 if done before):
    compiling them first where numba's cache is cold (one line on stderr says so)."""
    return load_fast_kernels()


#: The certificate's name in violations (it is not one of the paper's triples).
CERTIFICATE = "continuous-time certificate"


def _certificate_violation(cert: Certificate) -> ContractViolation:
    try:
        require_clear(cert, name=CERTIFICATE)
    except ContractViolation as exc:
        return exc
    raise AssertionError("require_clear accepted a certificate that is not clear")


#: The name of the exact re-decision in violations (like the certificate, not a triple).
EXACT = "exact re-decision of the path's cells"


def _exact_violation(e: ExactGaps) -> ContractViolation:
    first = e.undecided[0]
    return ContractViolation(EXACT, "exact.path_cells: a cell the path occupies is not proved "
                             "free in ball arithmetic (its float decision rests on rounding)",
                             {"undecided": len(e.undecided), "layer": first.layer,
                              "cell": first.cell, "gap_lower_m": first.gap_lower_m})


def _timed(fn: Callable[..., R], t: dict[str, float], key: str) -> Callable[..., R]:
    """``fn``, recording its own time in t[key] (so contract time can be told apart from it)."""
    def run(*args: Any) -> R:
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            t[key] = time.perf_counter() - t0
    return run


def plan_json(p: PlanResult, dr_bytes: bytes | None = None,
              witness_bytes: bytes | None = None, *, dr_sha256: str | None = None,
              witness_sha256: str | None = None, dr_store: str | None = None
              ) -> dict[str, Any]:
    """The plan.json document of docs/model.md §9 (keys are stable: add, never rename).

    ``witness_sha256`` (only when ``witness_bytes``, the witness file's, or the hash itself is
    given) is their sha256, so that `cfmpa check --witness` can tell a witness file of another
    run.

    ``dr_sha256`` is the sha256 of dr.npy's bytes (``dr_bytes``, by default ``npy_bytes(p.dr)``,
    what write_plan writes; or the hash itself, as write_plan gives it), so that a dr.npy from
    another run is detectable; a dr.zarr has the same one (runs/_drstore.py). ``dr_store``
    (``npy`` | ``zarr``, only when given: write_plan gives it) names the D_R file beside
    plan.json. In ``clearance``,
    ``min_m`` / ``t_s`` are the least SAMPLED distance and its instant (an upper bound on the
    true minimum); ``lower_bound_m`` is the PROVED lower bound over every instant.
    """
    if dr_sha256 is None:
        from ._drstore import dr_sha256_of  # npy_bytes(p.dr)'s hash, a layer at a time

        dr_sha256 = (dr_sha256_of(p.dr) if dr_bytes is None
                     else hashlib.sha256(dr_bytes).hexdigest())
    if witness_sha256 is None and witness_bytes is not None:
        witness_sha256 = hashlib.sha256(witness_bytes).hexdigest()
    r = p.search
    found = r.status is SearchStatus.FOUND
    g = p.grid
    return {
        "scenario": p.scenario.name,
        "scenario_sha256": p.scenario.sha256,
        "variant": p.variant.value,
        "grid": {"N": g.N, "m": g.m, "n": g.n, "dt": g.dt, "Tf": g.Tf, "lo": list(g.lo),
                 "h": list(g.h)},
        "status": r.status.value,
        "reason": r.reason,
        "path": [list(c) for c in r.path],
        "angles": [list(g.angles(c)) for c in r.path],
        "J1": r.J1 if found else None,
        "J2": r.J2 if found else None,
        "path_length": len(r.path),
        "free_fraction": p.free_fraction,
        "dr_sha256": dr_sha256,
        "kernel": p.kernel,
        "clearance": certificate_json(p.certificate) if p.certificate is not None else None,
        "tolerance_rad": (tolerance_rad(p.scenario, p.certificate)
                          if p.certificate is not None else None),
        "exact_gaps": p.exact.as_json() if p.exact is not None else None,
        # What the safety theorem does not yet cover here (docs/model.md §10): null, or e.g.
        # "tool: checked on samples and by the certificate, not yet by the safety theorem".
        "theorem_scope": theorem_scope(p.scenario),
        "contracts": p.contracts,
        "timings_s": {k: round(v, 6) for k, v in sorted(p.timings_s.items())},
        "versions": versions(),
    } | ({} if witness_sha256 is None else {"witness_sha256": witness_sha256}) | (
        {} if dr_store is None else {"dr_store": dr_store})


#: The executed motion of a found path, beside plan.json (docs/model.md §9, §12).
TRAJ_CSV = "traj.csv"


def write_plan(p: PlanResult, out: str | Path, *, witness: str | Path | None = None,
               store: str | None = None, built: BuiltStore | None = None
               ) -> tuple[Path, Path]:
    """Write DIR/dr.npy (or with ``store="zarr"`` DIR/dr.zarr; by default the one
    ``default_store`` picks for the grid's cells, docs/model.md §9) and DIR/plan.json, each
    atomically (temporary name, then rename); plan.json's dr_sha256 is the hash of the very
    bytes written (for dr.zarr, of the same array's .npy bytes) and its dr_store the store. A
    D_R of the other store left by an earlier run is removed. For a found path
    also DIR/traj.csv, its executed motion (one row per step, `cfmpa certify` reads it); with
    no path a traj.csv left by an earlier run is deleted. ``witness``: also write the search's
    witness there (npz, ``spec.Witness``; plan() with witness=True makes it), its hash in
    plan.json as ``witness_sha256``.

    dr.npy and the witness are streamed to their files (the witness layer by layer,
    ``spec.save_npz``) and hashed by reading the files back, so neither is held as bytes.
    ``built``: D_R is that store, built on Dask (runs/_drdask.py), which ``p.dr`` reads a
    layer at a time; it is renamed into place as DIR/dr.zarr (``store`` is then zarr) instead
    of written."""
    out = Path(out)
    witness_sha = None
    if witness is not None:
        if p.search.witness is None:
            raise ValueError("write_plan(witness=...) needs a plan made with witness=True")
        members = p.search.witness.npz_members()
        _, witness_sha = _write_streamed(witness, lambda fh: save_npz(fh, members))
    from ._drstore import _remove_other, default_store, write_dr

    if built is not None:
        store, dr_path, dr_sha = "zarr", built.publish(), built.sha256
        _remove_other(out, store)
    else:
        store = default_store(int(p.dr.size)) if store is None else store
        dr_path, dr_sha = write_dr(out, p.dr, store)
    if p.search.status is SearchStatus.FOUND:
        traj = executed_trajectory(p.scenario, p.grid, p.search.path)
        write_bytes_atomic(out / TRAJ_CSV, trajectory_csv(traj).encode())
    else:
        (out / TRAJ_CSV).unlink(missing_ok=True)
    doc = plan_json(p, dr_sha256=dr_sha, witness_sha256=witness_sha, dr_store=store)
    plan_path = write_bytes_atomic(out / "plan.json", dumps_json(doc).encode())
    return dr_path, plan_path


# --- cfmpa dr, cfmpa plan ---------------------------------------------------------------------


def run_dr(scenario_path: str | Path, variant: Variant | str, out: str | Path, *,
           kernel: str = "fast", name: str | None = None, stdout: TextIO | None = None,
           store: str | None = None, engine: EngineOptions | None = None) -> int:
    """`cfmpa dr`: build D_R of the scenario file for ``variant`` with the ``kernel`` pair
    (``impl.KERNELS``), write ``out``/dr.npy or dr.zarr (``store``, by default by the grid's
    cells: ``default_store``) atomically and print the grid and the free fraction; 0 (bad input
    raises InputError). ``name``: the scenario as the user gave it. ``engine`` (--workers K >= 1
    or --scheduler): D_R built on Dask a block of layers a task into dr.zarr
    (runs/_drdask.py); the cluster losing its workers is WorkersLost naming the command that
    runs it again. Without one, dr.zarr with the fast kernel is built the same way in this
    process (``_store_engine``), never whole."""
    from ..impl import kernels, resolved
    from ..spec import load_scenario
    from ._drstore import _remove_other, default_store, write_dr

    so = sys.stdout if stdout is None else stdout
    v = Variant(variant)
    s = load_scenario(scenario_path)
    g = make_grid(s)
    shape = (g.N + 1, g.m, g.n)
    engine = _store_engine(s, kernel, store, engine)
    if engine is not None:
        engine.check(kernel, store)
        from ._drdask import build_store

        t0 = time.perf_counter()
        with engine.rerun_on_lost(["dr", str(scenario_path if name is None else name),
                                   "--variant", v.value, "--out", str(out)]):
            built = build_store(s, v, Path(out) / "dr.zarr",
                                stream=so if engine.on_dask else None, **engine.kwargs())
        try:
            path = built.publish()
        finally:
            built.discard()
        _remove_other(out, "zarr")
        seconds, free = time.perf_counter() - t0, built.free_fraction
        parts = "  ".join(f"{key} {x:.3f} s" for key, x in built.timings_s.items()
                          if key != "dr_store") if engine.on_dask else ""
    else:
        store = default_store((g.N + 1) * g.m * g.n) if store is None else store
        kernel = resolved(kernel)           # numpy's while fast's compile (§7.5): say which ran
        build, _ = kernels(kernel)
        t0 = time.perf_counter()
        dr = build(s, v.value, g)
        seconds = time.perf_counter() - t0
        path, _ = write_dr(out, dr, store)
        free = 1.0 - float(dr.mean())
        parts = ""
    print(f"scenario  {s.name} ({scenario_path if name is None else name})", file=so)
    print(f"variant   {v.value} ({kernel} kernel)", file=so)
    print(f"grid      N={g.N} m={g.m} n={g.n} dt={g.dt} h=({g.h[0]:.6g}, {g.h[1]:.6g}) rad"
          f"  shape={shape}", file=so)
    print(f"free      {free:.4%} of cells", file=so)
    print(f"time      {seconds:.3f} s" + (f" ({parts})" if parts else ""), file=so)
    print(f"wrote     {path}", file=so)
    return 0


def _store_engine(s: Scenario, kernel: str, store: str | None,
                  engine: EngineOptions | None) -> EngineOptions | None:
    """Where D_R is built a block of layers at a time into dr.zarr (runs/_drdask.py
    ``build_store``, docs/model.md §9): on Dask (``engine`` --workers K >= 1 or --scheduler),
    or in this process (workers 0) whenever the store is zarr (``store``, or by default for
    the grid's cells) and the kernel the fast one, so that D_R is never held whole; None for
    the build of the whole array (dr.npy, or another kernel)."""
    if engine is not None and engine.on_dask:
        return engine
    from ._drstore import default_store

    g = make_grid(s)
    cells = (g.N + 1) * g.m * g.n
    chosen = default_store(cells) if store is None else store
    if kernel != "fast" or chosen != "zarr":
        _check_whole(cells, "--kernel" if kernel != "fast" else "--store",
                     kernel if kernel != "fast" else chosen)
        return None
    from ._drdask import EngineOptions

    return engine if engine is not None else EngineOptions()


def _check_whole(cells: int, option: str, value: str) -> None:
    """InputError naming ``option`` when D_R, built whole in memory (dr.npy, or a kernel other
    than the fast one), has more cells than ``spec.whole_max_cells()`` (docs/model.md §3)."""
    from ..spec import whole_max_cells

    budget = whole_max_cells()
    if cells > budget:
        raise InputError(option, value, f"keeps D_R whole in memory, and its {cells:,} cells are "
                                        f"over the budget of {budget:,} cells for a D_R held "
                                        f"whole (CFMPA_MAX_WHOLE_CELLS); use --store zarr with "
                                        f"the fast kernel, which streams it")


def run_plan(scenario_path: str | Path, variant: Variant | str, out: str | Path, *,
             contracts: Mode | str = "full", seed: int = 0, sample: int | None = None,
             kernel: str = "fast", witness: str | Path | None = None, name: str | None = None,
             stdout: TextIO | None = None, stderr: TextIO | None = None,
             store: str | None = None, engine: EngineOptions | None = None) -> int:
    """`cfmpa plan`: ``plan`` with the ``kernel`` pair, not stopping at a violation, then
    ``write_plan`` into ``out`` (D_R as ``store``, by default by the grid's cells; and the
    witness file); print the summary. ``engine`` (--workers K >= 1 or --scheduler): D_R built
    on Dask into dr.zarr as `cfmpa dr` does (runs/_drdask.py), then checked and searched here
    from the store a layer at a time (``ZarrDr.layers``, the searches' streamed input, §9),
    never read back whole; without one, a dr.zarr plan with the fast kernel goes the same way
    with the blocks built in this process (``_store_engine``, workers 0).

    0 when nothing was violated; 1 when a contract failed or the certificate is not clear (a
    contact or an undecided interval is a violation in every contracts mode, off included); the
    files are written all the same, as the evidence, and the summary says so on ``stderr``.
    Bad input raises InputError. ``name``: the scenario as the user gave it.
    """
    from ..impl import kernels, resolved
    from ..spec import load_scenario

    so = sys.stdout if stdout is None else stdout
    se = sys.stderr if stderr is None else stderr
    from ._drstore import zarr_threshold

    s = load_scenario(scenario_path)
    zarr_threshold()                  # a bad CFMPA_ZARR_CELLS is exit 2 before any work
    build, search = kernels(kernel)
    engine = _store_engine(s, kernel, store, engine)
    if engine is None:
        # plan.json names the kernel that ran: numpy's while fast's compile (§7.5)
        p = plan(s, variant, contracts=contracts, seed=seed, sample=sample, stop=False,
                 build=build, search=search, kernel=resolved(kernel),
                 witness=witness is not None)
        dr_path, plan_path = write_plan(p, out, witness=witness, store=store)
    else:
        engine.check(kernel, store)
        from ._drdask import build_store

        built: list[BuiltStore] = []

        def on_dask(s: Scenario, v: Variant, g: Grid) -> Any:
            b = build_store(s, v, Path(out) / "dr.zarr", keep_layers=True,
                            stream=so if engine.on_dask else None, **engine.kwargs())
            built.append(b)
            assert b.layers is not None
            return b.layers

        command = ["plan", str(scenario_path if name is None else name), "--variant",
                   Variant(variant).value, "--out", str(out), "--contracts", str(contracts),
                   *(["--witness", str(witness)] if witness is not None else [])]
        try:
            with engine.rerun_on_lost(command):
                p = plan(s, variant, contracts=contracts, seed=seed, sample=sample, stop=False,
                         build=on_dask, search=search, kernel=kernel,
                         witness=witness is not None)
            p.timings_s.update(built[0].timings_s)
            dr_path, plan_path = write_plan(p, out, witness=witness, built=built[0])
        finally:
            for b in built:
                b.discard()
    if p.search.witness is not None:
        p.search.witness.close()                  # written: its temporary files go now
    violations = p.violations
    g, r, t = p.grid, p.search, p.timings_s
    print(f"scenario  {s.name} ({scenario_path if name is None else name})", file=so)
    print(f"variant   {p.variant}", file=so)
    print(f"grid      N={g.N} m={g.m} n={g.n} dt={g.dt} h=({g.h[0]:.6g}, {g.h[1]:.6g}) rad",
          file=so)
    print(f"free      {p.free_fraction:.4%} of cells", file=so)
    if r.reason is None:
        print(f"status    {r.status}: J1={r.J1} J2={r.J2} length={len(r.path)} cells", file=so)
    else:
        print(f"status    {r.status}: {r.reason}", file=so)
    if p.certificate is not None:
        print(clearance_line(p.certificate), file=so)
    scope = theorem_scope(s)
    if scope is not None:
        print(f"scope     {scope}", file=so)
    print(f"contracts {p.settings.mode.value}: {p.checked} checks, {len(violations)} violations",
          file=so)
    print("time      " + "  ".join(f"{k} {v:.3f} s" for k, v in t.items()), file=so)
    written = [dr_path, plan_path] + ([Path(out) / TRAJ_CSV] if r.status is SearchStatus.FOUND
                                      else []) + ([Path(witness)] if witness else [])
    print(f"wrote     {', '.join(str(x) for x in written)}", file=so)
    for v in violations:
        print(f"violation {v.one_line()}", file=se)
    if violations:
        print(f"result    {len(violations)} violation(s): exit 1; the files above are written as "
              f"the evidence", file=se)
    return 1 if violations else 0


def clearance_line(c: Certificate) -> str:
    """The certificate in one line: the PROVED lower bound first, then the least sampled distance
    (an upper bound on the true minimum) and its instant."""
    sampled = (f"sampled minimum {c.min_clearance_m * 1000:.6g} mm at t={c.t_min_s:.4f} s "
               f"({c.intervals} intervals)")
    if c.clear:
        return (f"clearance clear: proved >= {c.lower_bound_m * 1000:.6g} mm at every instant; "
                f"{sampled}")
    if c.contact_detail is not None:
        d = c.contact_detail
        return (f"clearance NOT CLEAR: contact at t={d.t_s:.4f} s, "
                f"{contact_links_text(d.links)}, {d.segment}; {sampled}")
    return (f"clearance NOT CLEAR: {len(c.undecided)} interval(s) neither proved clear nor in "
            f"contact, first {c.undecided[0]} s; {sampled}")


def _write_streamed(path: str | Path, write: Callable[[Any], object]) -> tuple[Path, str]:
    """``write(fh)`` atomically (``cfmpa.files.write_atomic_with``); the path and the sha256 of
    the file written, read back in chunks."""
    target, sha = write_atomic_with(path, write, digest=True)
    assert sha is not None
    return target, sha
