"""`cfmpa check SCENARIO --dr FILE --plan FILE`: another planner's outputs against the spec.

The outputs are docs/model.md §9's dr.npy (or dr.zarr) and plan.json. Checked, all in full: D_R's
shape and dtype and Theorem 1/3's postcondition for the plan's variant at every cell (the spec's own regions);
the path by is_path; J1 and J2 as reported; optimality (or that no path exists) through a
witness verified by ``spec.check_witness`` (docs/model.md §11): the ``--witness`` file, else one
computed by the fast search, so that what is trusted is the spec's checker; the continuous-time
certificate. Also, when plan.json states them: the scenario's hash, the grid, the angles of the
path's cells, dr_sha256 against the dr file's bytes (a dr.zarr's: its array's .npy bytes; a
mismatch means the two files are not from the same run) and witness_sha256 against the witness file's.
Exit 0 when everything holds, 1 with a listing of what failed, 2 when an input cannot be read
(missing file, not .npy, a corrupt dr.zarr or one not of the grid's shape, bad JSON, missing or
mistyped keys), as ``file: error: ...``.
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import numpy.typing as npt

from ..errors import MISSING, ContractViolation, InputError, value_text
from ..files import LIMITS, mm_text, read_bounded
from ..spec import (
    Grid,
    Scenario,
    SearchResult,
    SearchStatus,
    Variant,
    Witness,
    certify,
    cost_failures,
    load_scenario,
    load_witness,
    make_grid,
    require_clear,
    search_triple,
)
from ._contracts import Mode, Settings, TripleRun, builtdr_post, search_post, search_pre
from ._drstore import load_dr
from ._plan import CERTIFICATE

__all__ = ["CheckLine", "CheckReport", "PlanDoc", "check_outputs", "read_dr", "read_plan",
           "run_check"]

#: Relative tolerance for plan.json's floats (grid dt, lo, h; angles) against the spec's.
FLOAT_TOL = 1e-9


@dataclass(frozen=True)
class PlanDoc:
    """What check reads from plan.json: the variant, the search's answer, and optional claims."""

    variant: Variant
    result: SearchResult
    sha256: str | None
    grid: dict[str, Any] | None
    angles: tuple[tuple[float, float], ...] | None
    dr_sha256: str | None = None
    witness_sha256: str | None = None
    #: The D_R store beside plan.json (``npy`` | ``zarr``), when plan.json names it.
    dr_store: str | None = None


@dataclass(frozen=True)
class CheckLine:
    """One line of the listing: ``ok``, ``FAIL`` or ``skip``, what, and the values if it failed;
    ``follows``: for a failure that follows from an earlier one, that one's ``what`` (its
    condition), which the listing names."""

    status: str
    what: str
    values: tuple[tuple[str, Any], ...] = ()
    follows: str | None = None


@dataclass(frozen=True)
class CheckReport:
    """Every check made, in order."""

    lines: tuple[CheckLine, ...]

    @property
    def ok(self) -> bool:
        return all(line.status != "FAIL" for line in self.lines)

    @property
    def failed(self) -> tuple[CheckLine, ...]:
        return tuple(line for line in self.lines if line.status == "FAIL")

    def text(self) -> str:
        out = []
        for line in self.lines:
            follows = "" if line.follows is None else (
                f" (follows from the failed {line.follows} above)")
            out.append(f"{line.status:<5} {line.what}{follows}")
            out += [f"      {value_text(name, value)}" for name, value in line.values]
        n = len(self.failed)
        derived = sum(x.follows is not None for x in self.failed)
        out.append("result: all checks hold" if n == 0 else
                   f"result: {n} of {sum(x.status != 'skip' for x in self.lines)} checks failed"
                   + (f", {derived} of them following from an earlier failure" if derived
                      else ""))
        return "\n".join(out)


def run_check(scenario_path: str | Path, dr_path: str | Path, plan_path: str | Path,
              witness_path: str | Path | None = None, *, stdout: TextIO | None = None,
              stderr: TextIO | None = None) -> int:
    """Check the outputs, print the listing on ``stdout``; 0 all hold, 1 some failed; unreadable
    input raises InputError (exit 2) before anything is printed. ``witness_path``: a witness
    file (`cfmpa plan --witness-out`) to verify instead of computing one; ``stderr`` is for
    errors only, which are raised."""
    so = sys.stdout if stdout is None else stdout
    s = load_scenario(scenario_path)
    # A dr.npy or a dr.zarr (checked against the grid before a chunk is read), and dr_sha256.
    dr, dr_sha = load_dr(dr_path, make_grid(s).shape)
    doc = read_plan(plan_path)
    witness = witness_sha = None
    if witness_path is not None:
        witness = load_witness(witness_path)
        witness_sha = _file_sha256(witness_path, "witness")
    print(f"check     {Path(dr_path)} and {Path(plan_path)} against {s.name} "
          f"({scenario_path}), variant {doc.variant.value}"
          + ("" if witness_path is None else f", witness {Path(witness_path)}"), file=so)
    report = check_outputs(s, dr, doc, dr_sha256=dr_sha, witness=witness,
                           witness_sha256=witness_sha)
    print(report.text(), file=so)
    return 0 if report.ok else 1


def _file_sha256(path: str | Path, field: str = "dr") -> str:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as exc:
        raise InputError(field, MISSING, f"cannot be read ({exc.strerror or exc})",
                         source=str(path)) from None


def read_dr(path: str | Path, expect: tuple[int, int, int] | None = None) -> npt.NDArray[Any]:
    """dr.npy (of any dtype: the check judges it) or dr.zarr (of the grid's shape ``expect``
    when given) as an array; InputError if unreadable, corrupt or over the cell budget
    (``runs/_drstore.py``'s ``load_dr``, which also gives dr_sha256)."""
    return load_dr(path, expect)[0]


def read_plan(path: str | Path) -> PlanDoc:
    """plan.json's keys that check needs (docs/model.md §9); InputError names a missing or bad key."""
    source = str(path)
    try:
        # Bounded: /dev/zero or a file cut short of its end is refused at the limit (§3).
        text = read_bounded(path, LIMITS["plan"], source, lines=False, field="plan").decode("utf-8")
    except UnicodeDecodeError:
        raise InputError("plan", MISSING, "is not UTF-8 text", source=source) from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError("json", MISSING, f"is not valid: {exc.msg} (column {exc.colno})",
                         source=source, line=exc.lineno) from None

    def bad(key: str, value: Any, message: str) -> InputError:
        return InputError(key, value, message, source=source)

    if not isinstance(doc, dict):
        raise bad("<document>", type(doc).__name__, "must be a JSON object")
    for key in ("variant", "status", "path", "J1", "J2"):
        if key not in doc:
            raise bad(key, MISSING, "is required (docs/model.md §9)")
    try:
        variant = Variant(doc["variant"])
    except ValueError:
        raise bad("variant", doc["variant"], "must be one of original, modified, tight") from None
    if doc["status"] not in ("found", "no_path"):
        raise bad("status", doc["status"], "must be 'found' or 'no_path'")
    path = doc["path"]
    if not isinstance(path, list) or not all(_is_cell(c) for c in path):
        raise bad("path", _short(path), "must be a list of [i, j] integer pairs")
    cells = tuple((int(c[0]), int(c[1])) for c in path)
    if doc["status"] == "found":
        for key in ("J1", "J2"):
            if not _is_int(doc[key]):
                raise bad(key, doc[key], "must be an integer when status is 'found'")
        if not cells:
            raise bad("path", [], "must not be empty when status is 'found'")
        result = SearchResult(SearchStatus.FOUND, None, cells, doc["J1"], doc["J2"])
    else:
        reason = doc.get("reason")
        result = SearchResult(SearchStatus.NO_PATH, None if reason is None else str(reason),
                              cells, None, None)
    sha = doc.get("scenario_sha256")
    if sha is not None and not isinstance(sha, str):
        raise bad("scenario_sha256", sha, "must be a string")
    dr_sha = doc.get("dr_sha256")
    if dr_sha is not None and not isinstance(dr_sha, str):
        raise bad("dr_sha256", dr_sha, "must be a string")
    witness_sha = doc.get("witness_sha256")
    if witness_sha is not None and not isinstance(witness_sha, str):
        raise bad("witness_sha256", witness_sha, "must be a string")
    dr_store = doc.get("dr_store")
    if dr_store is not None and dr_store not in ("npy", "zarr"):
        raise bad("dr_store", _short(dr_store), "must be \"npy\" or \"zarr\"")
    grid = doc.get("grid")
    if grid is not None and not isinstance(grid, dict):
        raise bad("grid", grid, "must be an object")
    angles = doc.get("angles")
    if angles is not None:
        if not isinstance(angles, list) or not all(
                isinstance(a, list) and len(a) == 2 and all(_is_number(x) for x in a)
                for a in angles):
            raise bad("angles", _short(angles), "must be a list of [t1, t2] number pairs")
        angles = tuple((float(a[0]), float(a[1])) for a in angles)
    return PlanDoc(variant, result, sha, grid, angles, dr_sha, witness_sha, dr_store)


def check_outputs(s: Scenario, dr: npt.NDArray[Any], doc: PlanDoc, *,
                  dr_sha256: str | None = None, witness: Witness | None = None,
                  witness_sha256: str | None = None) -> CheckReport:
    """Every check of this module on already-read outputs (see the module docstring).

    ``dr_sha256`` is the hash of the dr file's bytes, checked against plan.json's when both
    are known; likewise ``witness_sha256``, the witness file's. ``witness`` is verified for
    post.optimal; without it the fast search computes one."""
    g = make_grid(s)
    lines: list[CheckLine] = []
    if doc.dr_sha256 is not None and dr_sha256 is not None:
        lines.append(_line(doc.dr_sha256 == dr_sha256, "plan.json dr_sha256 is the dr file's "
                           "(the two files are from one run)",
                           (("plan's", doc.dr_sha256), ("file's", dr_sha256))))
    if doc.witness_sha256 is not None and witness_sha256 is not None:
        lines.append(_line(doc.witness_sha256 == witness_sha256, "plan.json witness_sha256 is "
                           "the witness file's", (("plan's", doc.witness_sha256),
                                                  ("file's", witness_sha256))))
    if doc.sha256 is not None and s.sha256:
        lines.append(_line(doc.sha256 == s.sha256, "plan.json scenario_sha256 is the scenario "
                           "file's", (("plan's", doc.sha256), ("file's", s.sha256))))
    if doc.grid is not None:
        lines.append(_grid_line(g, doc.grid))
    full = Settings(Mode.FULL)
    post = builtdr_post(s, doc.variant, g, dr, full)
    lines += _run_lines(post)
    start, goal = s.right.start_cell, s.right.goal_cell
    r = doc.result
    shape_ok = not any(f.condition == "post.shape" for f in post.failures)
    if shape_ok:
        lines += _run_lines(search_pre(doc.variant, g, dr, start, goal, post))
        lines += _run_lines(search_post(doc.variant, dr, start, goal, r, full, witness=witness))
    else:
        # J1 and J2 are the path's alone: a bad D_R does not excuse misreported costs.
        costs = cost_failures(r)
        what = f"{search_triple(doc.variant).name} post.costs"
        if r.status is not SearchStatus.FOUND:
            lines.append(CheckLine("ok", f"{what}: nothing to check: no path reported"))
        elif not costs:
            lines.append(CheckLine("ok", f"{what}: J1 and J2 recomputed"))
        else:
            lines += [CheckLine("FAIL", f"{what}: {f.message}", f.values) for f in costs]
        lines.append(CheckLine("skip", "the path (is_path, optimality): D_R has the wrong shape"))
    found = r.status is SearchStatus.FOUND
    if found and doc.angles is not None:
        lines.append(_angles_line(g, r.path, doc.angles))
    inside = all(0 <= i < g.m and 0 <= j < g.n for i, j in r.path)
    if found and inside:
        cert = certify(s, g, r.path)
        try:
            require_clear(cert, name=CERTIFICATE)
            lines.append(CheckLine("ok", f"{CERTIFICATE}: clear, proved lower bound "
                                   f"{mm_text(cert.lower_bound_m)} at every instant; sampled "
                                   f"minimum {mm_text(cert.min_clearance_m)} at t = "
                                   f"{cert.t_min_s:.6g} s ({cert.intervals} intervals)"))
        except ContractViolation as exc:
            lines.append(CheckLine("FAIL", f"{exc.triple}: {exc.condition}",
                                   tuple(exc.values.items())))
    elif found:
        lines.append(CheckLine("skip", f"{CERTIFICATE}: the path leaves the grid"))
    return CheckReport(_consequences(lines))


#: A failed condition that follows from another's failure: the condition (its suffix in the
#: listing's ``what``) -> the conditions it follows from, the first failed one named. D_R that
#: fails post.cells fails searchoptpath's pre.dr.spec (the same check); a path judged against
#: such a D_R may be blocked in it (is_path's ``blocked`` clause), and optimality is then judged
#: against it too (docs/model.md §7.3).
FOLLOWS: dict[str, tuple[str, ...]] = {
    "pre.dr.spec": ("post.cells",),
    "post.is_path": ("post.cells",),
    "post.optimal": ("post.is_path", "post.cells"),
}


def _condition(line: CheckLine) -> str | None:
    """The contract condition a line reports (``Theorem 4 post.is_path: ...`` ->
    ``post.is_path``), or None for another check."""
    head = line.what.split(":", 1)[0].split()
    return head[-1] if head and head[-1].startswith(("pre.", "post.")) else None


def _consequences(lines: list[CheckLine]) -> tuple[CheckLine, ...]:
    """``lines`` with each failure that follows from an earlier failure (``FOLLOWS``) marked;
    an is_path failure follows from a bad D_R only when its clause is ``blocked`` (a jump or a
    wrong end is the path's own)."""
    failed: dict[str, str] = {}                   # condition -> the what of its first failure
    out = []
    for line in lines:
        cond = _condition(line)
        if line.status == "FAIL" and cond is not None:
            values = dict(line.values)
            own = cond == "post.is_path" and values.get("clause", "blocked") != "blocked"
            cause = next((failed[c] for c in FOLLOWS.get(cond, ()) if c in failed), None)
            if cause is not None and not own:
                line = CheckLine(line.status, line.what, line.values, follows=cause)
            failed.setdefault(cond, line.what.split(":", 1)[0])
        out.append(line)
    return tuple(out)


def _run_lines(run: TripleRun) -> list[CheckLine]:
    out = []
    for c in run.checks:
        what = f"{run.triple.name} {c.condition}: {c.scope}"
        if c.ok is None:
            out.append(CheckLine("skip", what))
            continue
        fails = [f for f in run.failures if f.condition == c.condition]
        if not fails:
            out.append(CheckLine("ok", what))
        for f in fails:
            values = f.values + ((("instances failing", f.count),) if f.count > 1 else ())
            out.append(CheckLine("FAIL", f"{run.triple.name} {c.condition}: {f.message}", values))
    return out


def _line(ok: bool, what: str, values: tuple[tuple[str, Any], ...]) -> CheckLine:
    return CheckLine("ok", what) if ok else CheckLine("FAIL", what, values)


def _close(a: Any, b: float) -> bool:
    return _is_number(a) and abs(float(a) - b) <= FLOAT_TOL * max(1.0, abs(b))


def _grid_line(g: Grid, claimed: dict[str, Any]) -> CheckLine:
    want: dict[str, Any] = g.as_json()
    wrong: list[tuple[str, Any]] = []
    for key in ("N", "m", "n"):
        if key in claimed and claimed[key] != want[key]:
            wrong.append((key, claimed[key]))
    for key in ("dt", "Tf"):
        if key in claimed and not _close(claimed[key], want[key]):
            wrong.append((key, claimed[key]))
    for key in ("lo", "h"):
        if key in claimed:
            v = claimed[key]
            if not (isinstance(v, list) and len(v) == 2
                    and all(_close(x, y) for x, y in zip(v, want[key]))):
                wrong.append((key, v))
    values = tuple((f"plan's {k}", v) for k, v in wrong) + tuple(
        (f"spec's {k}", want[k]) for k, _ in wrong)
    return _line(not wrong, "plan.json grid is the scenario's (docs/model.md §2)", values)


def _angles_line(g: Grid, path: tuple[tuple[int, int], ...],
                 angles: tuple[tuple[float, float], ...]) -> CheckLine:
    if len(angles) != len(path):
        return CheckLine("FAIL", "plan.json angles: one pair per path cell",
                         (("angles", len(angles)), ("cells", len(path))))
    for k, (c, a) in enumerate(zip(path, angles)):
        want = (float(g.angle(0, c[0])), float(g.angle(1, c[1])))
        if not (_close(a[0], want[0]) and _close(a[1], want[1])):
            return CheckLine("FAIL", "plan.json angles are the path cells' grid angles",
                             (("step", k), ("cell", list(c)), ("angles", list(a)),
                              ("grid angles", list(want))))
    return CheckLine("ok", f"plan.json angles are the path cells' grid angles ({len(path)})")


def _is_int(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _is_number(x: Any) -> bool:
    return (isinstance(x, (int, float)) and not isinstance(x, bool)
            and math.isfinite(float(x)))


def _is_cell(c: Any) -> bool:
    return isinstance(c, list) and len(c) == 2 and all(_is_int(x) for x in c)


def _short(x: Any) -> Any:
    text = repr(x)
    return x if len(text) <= 80 else text[:77] + "..."
