"""`cfmpa audit`: one self-contained HTML report for a safety reviewer, and its JSON twin.

Content, in order (docs/model.md §8): the verdict per workcell; provenance; the obligations'
summary table (theorems and definitional ones counted apart) with the prove run's negative
controls, and each obligation;
the assumptions ledger; the findings about the paper, drawn; the mutation self-check; per
scenario the plans of the three variants with contracts, certificate, each found plan's
tolerance tube (docs/model.md §12) and pictures; per audited workcell one monitored simulated
run of its modified plan, with and without an injected excursion (or why there is none); the
seeded comparison campaign. Where a part's data is not available in this run, the part says so.
Each part is a ``Section`` of SECTIONS (``_sections``): its compute, its checks (its rows of
the verdict, in the sections' order) and its template file, section_<key>.html.

report.json holds every number of the HTML (not the pictures). For the same inputs and version
it is the same apart from the provenance (date, git state, command line), the times (keys
``seconds``, ``timings_s``, ``mean_seconds``) and, after a fresh run of the obligations, the
total time in ``obligations.note``. Obligation data: see ``_obligations`` (results.json when
given, else a fresh run).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import io
import math
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, TextIO, cast

import jinja2
import markupsafe
import numpy as np

from ..errors import CfmpaError, InputError
from ..files import jsonable, write_bytes_atomic, write_json
from ..runs import Campaign, load_campaign, run_campaign
from ..scenarios import BUNDLED_DIR
from ..spec import (
    Scenario,
    SearchStatus,
    Variant,
    certify_trajectory,
    executed_trajectory,
    load_scenario,
    theorem_scope,
    tolerance_rad,
    tube_lipschitz,
)
from . import _figures as F
from ._compare import campaign_json, format_campaign
from ._findings import (
    Finding,
    early_arrival_finding,
    inconsistency_finding,
    naive_hull_finding,
    prop8_finding,
    sample_clearance,
)
from ._obligations import (
    ProofData,
    card_groups,
    control_summary,
    load_proofs,
    load_selftest,
    read_results,
    summary_table,
)
from ._provenance import VERSION_GROUPS, provenance
from ._sections import Section, compute_order, numbers, verdict_of

__all__ = ["AuditResult", "FORMAT", "SECTIONS", "DEFAULT_COMPARE_N", "build_audit", "contract_rows",
           "render_html", "run_audit", "write_report", "default_scenarios_dir",
           "MONITOR_VARIANT", "MONITOR_SIMULATION", "MONITOR_EXCURSION", "MONITOR_MAX_SAMPLES",
           "tube_problems", "monitor_problems", "monitor_settings", "workcell_summary"]

#: report.json's format name and version (bump the version when a key changes meaning).
FORMAT = {"name": "cfmpa-audit-report", "version": 1}
DEFAULT_COMPARE_N = 100
#: plan.json keys a variant's entry copies when the plan has them (the schema allows them).
_OPTIONAL_PLAN_KEYS = ("kernel", "dr_sha256", "tolerance_rad")
#: The scenarios the findings are shown on (file stems under the scenarios folder).
FINDING_SCENARIOS = {"naive_hull": "default", "inconsistency": "original-fails",
                     "prop8_literal": "original-fails", "is_path_flaw": "early-arrival"}
#: The monitored runs (docs/model.md §8, §12): each audited workcell's plan of this variant,
#: logged by the tracking model of `cfmpa simulate` with these settings, then again with the
#: excursion added (the README's example); ``monitor_settings`` scales them to a narrow tube and
#: moves the excursion into a short motion.
MONITOR_VARIANT = Variant.MODIFIED
MONITOR_SIMULATION = {"lag_s": 0.001, "noise_rad": 0.002, "seed": 0, "period_s": 0.001,
                      "tail_s": 0.2}
MONITOR_EXCURSION = {"t_s": 0.6, "joint": "right1", "rad": 0.02, "duration_s": 0.05}
#: The most samples a monitored run's log may have (a narrower tube is not demonstrated).
MONITOR_MAX_SAMPLES = 1_000_000
#: cfmpa certify's proved bound on traj.csv agrees with the plan's to within this (m).
BOUND_AGREEMENT_M = 1e-12


@dataclass(frozen=True)
class AuditResult:
    """The report's data (report.json), its pictures (id -> Figure) and the sections it was
    built from, in the order they are shown (empty: SECTIONS)."""

    doc: dict[str, Any]
    figures: dict[str, F.Figure]
    sections: tuple[Section, ...] = ()


class _Progress:
    """A line per finished stage with its wall-clock time, on the stream given (None: silent).
    Lines are written when a stage ends, so a nested stage (a plan) comes before its caller's."""

    def __init__(self, stream: TextIO | None) -> None:
        self.stream = stream
        self.start = time.perf_counter()

    @contextlib.contextmanager
    def stage(self, label: str) -> Iterator[None]:
        t0 = time.perf_counter()
        yield
        self._line(label, time.perf_counter() - t0)

    def total(self) -> None:
        self._line("audit, in all", time.perf_counter() - self.start)

    def _line(self, label: str, seconds: float) -> None:
        if self.stream is not None:
            self.stream.write(f"audit: {label:<52} {seconds:7.1f} s\n")
            self.stream.flush()


def default_scenarios_dir() -> Path:
    """The bundled scenarios (the checkout's scenarios/, or the installed package's)."""
    return BUNDLED_DIR


def run_audit(scenarios: list[str] | None, out_dir: str, *, argv: list[str] | None = None,
              proofs_json: str | Callable[[], str] | None = None,
              scenarios_dir: str | None = None,
              contracts: str = "full", compare_n: int = DEFAULT_COMPARE_N,
              compare_seed: int = 0, expected_ids: Sequence[str] | None = None,
              campaign: str | Path | None = None, progress: TextIO | None = None,
              stdout: TextIO | None = None) -> int:
    """Write ``out_dir``/report.json and ``out_dir``/report.html (each atomically); print a summary
    on ``stdout`` (default sys.stdout), and a line per stage with its time on ``progress``.

    ``scenarios``: scenario files (None: every scenarios/*.toml). ``proofs_json``: a results.json
    of ``make prove`` to report (None: run the obligations afresh). Exit code 0 when no check of
    the report failed (see "What this run checked"; an incomplete report, with a check not
    available, is 0 too and says "incomplete" in its last line and its status), 1 otherwise
    (the report is written either way), 2 for bad input. ``expected_ids``: the obligation ids
    the report must find (None: every obligation of the prove machinery). ``campaign``: a
    folder written by ``cfmpa compare --out``, whose recorded campaign the report shows instead
    of running one.
    ``progress``: where to write a line per stage with its time (``cfmpa audit``: stderr).
    """
    stages = _Progress(progress)
    result = build_audit(scenarios, argv=argv, proofs_json=proofs_json,
                         scenarios_dir=scenarios_dir, contracts=contracts, compare_n=compare_n,
                         compare_seed=compare_seed, expected_ids=expected_ids,
                         campaign=campaign, progress=stages)
    with stages.stage("write report.html and report.json"):
        html_path, json_path = write_report(result, out_dir)
    stages.total()
    import sys

    so = sys.stdout if stdout is None else stdout
    v = result.doc["verdict"]
    for item in v["items"]:
        state = {True: "ok", False: "FAILED", None: "not available"}[item["ok"]]
        print(f"{item['check']:<38} {state}: {item['detail']}", file=so)
    print(f"{'overall':<38} {v['status']}"
          + (f" (not available: {', '.join(v['not_available'])})" if v["not_available"] else ""),
          file=so)
    print(f"wrote     {html_path} ({html_path.stat().st_size} bytes), {json_path}", file=so)
    return 0 if v["ok"] else 1


def write_report(result: AuditResult, out_dir: str | Path) -> tuple[Path, Path]:
    """Write report.json, then report.html, each atomically; returns (html path, json path)."""
    out = Path(out_dir)
    json_path = write_json(out / "report.json", result.doc)
    html_path = write_bytes_atomic(out / "report.html", render_html(result).encode("utf-8"))
    return html_path, json_path


def build_audit(scenarios: Sequence[str] | None, *, argv: Sequence[str] | None = None,
                proofs_json: str | Callable[[], str] | None = None,
                scenarios_dir: str | None = None,
                contracts: str = "full", compare_n: int = DEFAULT_COMPARE_N,
                compare_seed: int = 0, expected_ids: Sequence[str] | None = None,
                campaign: str | Path | None = None,
                progress: TextIO | _Progress | None = None,
                sections: Sequence[Section] | None = None) -> AuditResult:
    """Compute everything the report shows (no files written): each of ``sections`` (default
    SECTIONS) in ``compute_order``, then their ``finish`` steps and the verdict, their checks. A
    callable ``proofs_json`` is called for the results.json path once everything else is
    computed (the proofs' sections are deferred). ``progress``: a stream for a line per stage
    (findings, each plan, each scenario's figures, the monitored run, the campaign, the proofs)
    with its time."""
    stages = progress if isinstance(progress, _Progress) else _Progress(progress)
    sdir = Path(scenarios_dir) if scenarios_dir is not None else default_scenarios_dir()
    paths = _scenario_paths(scenarios, sdir)
    loaded = [load_scenario(p) for p in paths]          # input errors before any work
    stems: dict[str, Path] = {}
    for p in paths:   # per-scenario obligation ids carry the stem, so it must be unique
        if p.stem in stems:
            raise InputError("scenarios", str(p), f"has the same stem {p.stem!r} as "
                             f"{stems[p.stem]}: their obligation ids would clash; rename one")
        stems[p.stem] = p
    if isinstance(compare_n, bool) or not isinstance(compare_n, int) or compare_n < 0:
        raise InputError("compare_n", compare_n, "must be an integer >= 0 (0: no campaign)")
    recorded = None if campaign is None else load_campaign(campaign)   # input errors first
    if isinstance(proofs_json, (str, Path)):
        read_results(proofs_json)        # unreadable results: said now, not after the plans
    chosen = tuple(SECTIONS if sections is None else sections)
    ctx = _Context(sdir=sdir, paths=paths, loaded=loaded, given=bool(scenarios),
                   argv=argv, compare_n=compare_n, compare_seed=compare_seed,
                   recorded=recorded, campaign=campaign, proofs_json=proofs_json,
                   expected_ids=expected_ids, stages=stages, plans=_Plans(contracts, stages))
    if any(sec.deferred for sec in chosen):
        ctx.start_proofs()              # discharged side by side with the other sections
    try:
        for sec in compute_order(chosen):
            parts = sec.compute(ctx)
            if set(parts) != set(sec.keys):
                raise ValueError(f"section {sec.key!r} computed {sorted(parts)}, "
                                 f"not {list(sec.keys)}")
            ctx.doc.update(parts)
    finally:
        if ctx.background is not None:  # not taken (an error): the run is ended, not left
            ctx.background.close()
    for sec in chosen:
        if sec.finish is not None:
            sec.finish(ctx.doc)
    # report.json's keys are sorted when written; here the parts in the sections' order.
    doc = {"format": FORMAT, **{k: ctx.doc[k] for sec in chosen for k in sec.keys},
           "verdict": verdict_of(ctx.doc, chosen)}
    return AuditResult(doc=doc, figures=ctx.figures, sections=chosen)


@dataclass
class _Context:
    """What the sections are computed from: the inputs, the plans and pictures shared between
    sections, the proofs (read or discharged once, on first use) and the parts computed so far
    (``doc``)."""

    sdir: Path
    paths: list[Path]
    loaded: list[Scenario]
    given: bool                 # the scenarios were named (their own obligations are expected)
    argv: Sequence[str] | None
    compare_n: int
    compare_seed: int
    recorded: Campaign | None
    campaign: str | Path | None
    proofs_json: str | Callable[[], str] | None
    expected_ids: Sequence[str] | None
    stages: _Progress
    plans: _Plans
    figures: dict[str, F.Figure] = dataclasses.field(default_factory=dict)
    doc: dict[str, Any] = dataclasses.field(default_factory=dict)
    _proofs: ProofData | None = None
    background: _FreshProofs | None = None   # the fresh run, started early (``start_proofs``)

    def proofs(self) -> ProofData:
        """The obligation data; the user's workcells are the ones to prove: given files bring
        their own per-scenario obligations (the bundled set, by default, its pinned ones)."""
        if self._proofs is None:
            source = self.proofs_json
            with self.stages.stage("proofs (" + ("discharged afresh" if source is None else
                                                "read from the prove run") + ")"):
                got, self.background = (self.background.result() if self.background else None,
                                        None)
                self._proofs = got if got is not None else self._load(
                    source() if callable(source) else source, self.stages.stream)
        return self._proofs

    def _load(self, source: str | None, progress: TextIO | None) -> ProofData:
        return load_proofs(source, self.sdir, self.expected_ids,
                           files=self.paths if self.given else None, progress=progress)

    def start_proofs(self) -> None:
        """A fresh run of the obligations begun now, in a forked process, while this one
        computes the other sections (``_FreshProofs``); ``proofs`` takes its data."""
        if self.proofs_json is None and self._proofs is None and self.background is None:
            # The prove machinery imported and the negative controls listed (their
            # compositions' Z3 terms built) here, before the fork (docs/model.md §8): this
            # process needs them anyway (``_control_checkers``), and the fresh run inherits
            # both instead of doing the same work again, 0.9 s of CPU
            # (tests/report/test_fresh_inherits.py). A failure here is raised where the list
            # is used, as before.
            with contextlib.suppress(Exception):
                _control_checkers()
            self.background = _FreshProofs(lambda told: self._load(None, told),
                                           self.stages.stream)


class _FreshProofs:
    """``run`` (the fresh prove run: its own worker processes, docs/model.md §8) in a forked
    process begun at once; ``result`` waits for its ProofData, which comes back pickled, the
    same data as run here. Its line per group goes straight to ``stream`` when that is a file
    (the terminal: as each group ends), else back with the data. An exception raised there is
    raised by ``result``; a process that ends without an answer gives None (the caller then
    runs the obligations itself). ``close`` ends a run whose result is not wanted."""

    def __init__(self, run: Callable[[TextIO | None], ProofData], stream: TextIO | None) -> None:
        import multiprocessing
        import sys

        mp = multiprocessing.get_context("fork")
        self.stream = stream
        self._recv, send = mp.Pipe(duplex=False)
        direct = _file_stream(stream)
        for f in (sys.stdout, sys.stderr, stream):
            if f is not None:
                f.flush()
        self._proc = mp.Process(target=_fresh_child, args=(run, send, direct, stream is None),
                                name="cfmpa-audit-proofs")
        self._proc.start()
        send.close()
        _own_group(self._proc.pid)

    def result(self) -> ProofData | None:
        try:
            while True:
                try:
                    kind, value = self._recv.recv()
                except Exception:  # noqa: BLE001 - ended, died, or an answer that won't unpickle
                    return None
                if kind != "line":
                    break
                if self.stream is not None:
                    self.stream.write(value)
                    self.stream.flush()
        finally:
            self._proc.join(timeout=10)        # it ends once its answer is sent
            self.close()
        if kind == "raised" and isinstance(value, BaseException):
            raise value
        return value if isinstance(value, ProofData) else None

    def close(self) -> None:
        """End the run (its process group: its workers and cvc5 too) unless it has ended."""
        import os
        import signal

        if self._proc.is_alive() and self._proc.pid is not None:
            try:
                os.killpg(self._proc.pid, signal.SIGTERM)
            except OSError:
                self._proc.terminate()
        self._proc.join()
        self._recv.close()


def _own_group(pid: int | None) -> None:
    """Make ``pid`` the leader of a process group of its own (called in both processes, so it
    holds whichever runs first): ``_FreshProofs.close`` ends it with all its processes."""
    import contextlib
    import os

    with contextlib.suppress(OSError):  # it has ended already, or no such call here
        os.setpgid(pid or 0, pid or 0)


class _Lines(io.TextIOBase):
    """A stream whose lines go back to the parent through ``send`` (the child's progress)."""

    def __init__(self, send: Any) -> None:
        self._send = send

    def write(self, text: str) -> int:
        self._send.send(("line", text))
        return len(text)


def _file_stream(stream: TextIO | None) -> TextIO | None:
    """``stream`` if a forked process can write to it (it has a file descriptor), else None."""
    try:
        stream.fileno()  # type: ignore[union-attr]
    except (AttributeError, OSError, ValueError):
        return None
    return stream


def _fresh_child(run: Callable[[TextIO | None], ProofData], send: Any,
                 direct: TextIO | None, silent: bool) -> None:
    import os

    from ..impl import set_kernel_threads

    _own_group(None)
    set_kernel_threads(1)          # beside this audit's own process
    code = 0
    try:
        lines = cast(TextIO, _Lines(send))  # an io.TextIOBase: a text stream, TextIO but by name
        told = None if silent else (direct if direct is not None else lines)
        send.send(("done", run(told)))
    except BaseException as exc:   # noqa: BLE001 - handed to the parent, raised there
        try:
            send.send(("raised", exc))
        except Exception:          # noqa: BLE001 - unpicklable: the parent runs it itself
            code = 1
    finally:
        if direct is not None:
            direct.flush()
    os._exit(code)


def _template_source(name: str) -> str:
    """A template of this package by file name (the page, and each section's)."""
    return resources.files("cfmpa.report").joinpath(name).read_text(encoding="utf-8")


def template_env() -> jinja2.Environment:
    """The Jinja environment the page and each section's template are rendered in."""
    env = jinja2.Environment(autoescape=jinja2.select_autoescape(["html"], default=True),
                             undefined=jinja2.StrictUndefined, trim_blocks=True,
                             lstrip_blocks=True, keep_trailing_newline=True,
                             loader=jinja2.FunctionLoader(lambda n: _template_source(n)))
    env.filters.update(num=_num, pct=_pct, mm=_mm, secs=_secs, s3=_s3, anchor=_anchor)
    env.tests["control_id"] = lambda i: str(i).startswith("Control.")   # a negative control's id
    env.globals["version_groups"] = VERSION_GROUPS
    env.globals["version_grouped"] = [k for _, keys in VERSION_GROUPS for k in keys]
    return env


def render_html(result: AuditResult) -> str:
    """The self-contained HTML page (CSS inline, pictures as data URIs, no external URL): the
    page's frame, then each section's template in the order of the result's sections."""
    env = template_env()
    ob = result.doc["obligations"]
    by_id = {r["id"]: r for r in ob["items"]}
    cards = [{**g, "rows": [by_id[i] for i in g["ids"]]} for g in ob["cards"]]
    # The checkers' controls in a table; the compositions' (a premise left out each) folded.
    ctl = result.doc["controls"]["items"]
    premise = [c for c in ctl if c["checker"].startswith("Safety.")]
    groups = ([c for c in ctl if not c["checker"].startswith("Safety.")], premise)
    sections = result.sections or SECTIONS
    number = numbers(sections)
    contents = [markupsafe.Markup(env.from_string(entry).render(doc=result.doc))
                for sec in sections for entry in sec.contents_entries()]
    return env.get_template("template.html").render(
        doc=result.doc, figures=result.figures, cards=cards, columns=ob["summary"]["columns"],
        control_groups=groups, sections=sections, contents=contents, number=number)


def _obligations_part(proofs: ProofData) -> dict[str, Any]:
    """The report's "obligations" part."""
    return {
        "available": proofs.available, "source": proofs.source, "note": proofs.note,
        "summary": summary_table(proofs.rows),
        "cards": card_groups(proofs.rows),
        "items": [r.as_json() for r in proofs.rows],
        "missing_ids": list(proofs.missing_ids), "unexpected_ids": list(proofs.unexpected_ids),
        "all_as_expected": (all(r.as_expected for r in proofs.rows) and not proofs.missing_ids
                            and not proofs.unexpected_ids) if proofs.available else None,
        "run": proofs.run, "not_run": list(proofs.not_run),
        "depth": {"measures": proofs.depth_measures or DEPTH_MEASURES,
                  "nonlinear_vcs": sum(v.nonlinear for r in proofs.rows for v in r.vcs),
                  "vcs": sum(len(r.vcs) for r in proofs.rows)},
    }


def _assumptions_part(proofs: ProofData) -> dict[str, Any]:
    """The report's "assumptions" part: the ledger."""
    return {"available": proofs.ledger_available,
            "source": proofs.source if proofs.ledger_available else
            "not available in this run", "entries": list(proofs.ledger)}


def _proof_sections(proofs: ProofData) -> dict[str, Any]:
    """The report's "obligations", "controls" and "assumptions" parts."""
    return {"obligations": _obligations_part(proofs), "controls": _controls_part(proofs),
            "assumptions": _assumptions_part(proofs)}


#: What an obligation's depth measures, when results.json does not say (an older file).
DEPTH_MEASURES = ("quantifier instantiation: the weakest reasoning that proves a VC, "
                  "propositional, ground or full; nonlinear arithmetic is flagged apart")


def _controls_part(proofs: ProofData) -> dict[str, Any]:
    """The negative controls of the prove run (docs/model.md §10.3): seeded wrong inputs each
    checker must reject, and each Safety composition without one of its premises, which must
    not be proved. ``available`` False: none in this data (the note says why)."""
    rows = proofs.controls
    return {"available": bool(rows), "note": proofs.controls_note,
            "summary": control_summary(rows or ()),
            "items": [r.as_json() for r in rows or ()],
            "missing_ids": list(proofs.missing_controls)}


def _controls_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    """The verdict's check of the negative controls: every one ended as it expects, and none
    that a whole prove run has is missing; None when the data has none (a fresh run)."""
    c = doc["controls"]
    check = "negative controls as expected"
    missing = c["missing_ids"]
    if not c["available"] and not missing:
        return _item(check, None, c["note"])
    bad = [f"{i['id']} ({i['outcome']}, expected {' or '.join(i['expected'])})"
           for i in c["items"] if not i["ok"]]
    outcomes = ", ".join(f"{k} {v}" for k, v in c["summary"].items()
                         if k not in ("total", "as_expected"))
    return _item(check, not bad and not missing,
                 f"{c['summary']['as_expected']} of {c['summary']['total']}"
                 + (f" ({outcomes})" if outcomes else "")
                 + (f"; not as expected: {', '.join(bad)}" if bad else "")
                 + (f"; missing: {len(missing)} of the prove run's controls (e.g. {missing[0]})"
                    if missing else ""))


def _relate(doc: dict[str, Any]) -> None:
    """Give each finding the obligations that state it (by id prefix), with their verdicts."""
    for f in doc["findings"]:
        f["related_obligations"] = [{"id": r["id"], "verdict": r["verdict"], "badge": r["badge"]}
                                    for r in doc["obligations"]["items"]
                                    if any(r["id"].startswith(pre) for pre in f["related"])]


# --- Section 1: the verdict per workcell -------------------------------------------------------

#: What a row's verdict rests on, by ledger id prefix (docs/model.md §6.3, §10): a found plan's
#: safety is the certificate's (§7.2) and the end-to-end theorem's, whose scope (A11) is A1's
#: model, A2, A3 and A4; A5 (the while-language models) is not needed where cfmpa prove checked
#: the compiled code's output for that workcell and variant (translation validation, §7.4).
#: "No path" rests on the cells' float decisions (A2) and on the search's contract (A6) unless a
#: witness was checked (the contracts' post.optimal, or the translation check).
_SAFETY_ASSUMPTIONS = ("A1", "A2", "A3", "A4", "A11")
_NO_PATH_ASSUMPTIONS = ("A1", "A2")
#: The scenario-independent obligations a found plan's "safe" rests on, by id prefix: the safety
#: theorem's parts (§10: ``Safety.<variant>.*`` of the row's variant only, and every ``Safety.*``
#: of no variant), the certificate's bound (§7.2: "certified clear") and the tolerance tube the
#: row shows (§12). Taken from the prove machinery's ids (``cfmpa.proofs.FIXED_IDS``), so a part
#: added there is required here too.
ROW_OBLIGATION_PREFIXES = ("Safety.", "Certificate.", "Tolerance.")
_VARIANTS = tuple(v.value for v in Variant)


def _tools_or_heights(s: Scenario) -> bool:
    """Whether a workcell has a tool or a height interval: its safety rests on ledger A13 too."""
    return any(arm.tool is not None or arm.z is not None for arm in (s.left, s.right))


def row_requirements(stem: str, variant: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(obligation ids, control ids) a found plan's row of workcell ``stem`` (its file's stem)
    and ``variant`` rests on: ROW_OBLIGATION_PREFIXES' ids of the prove machinery, of this
    variant or none; the workcell's ``Scenario.<stem>.*`` checks (the translation check of this
    variant only, §7.4); and the negative controls (§10) of every checker the argument reads
    and of each of those obligations (``Control.Safety.<variant>.composition.without[k]``)."""
    from ..proofs import FIXED_IDS, SCENARIO_CHECKS, scenario_check_id

    def of_row(i: str) -> bool:
        parts = i.split(".")
        return i.startswith(ROW_OBLIGATION_PREFIXES) and (
            len(parts) < 3 or parts[1] not in _VARIANTS or parts[1] == variant)

    obligations = tuple(i for i in FIXED_IDS if of_row(i)) + tuple(
        scenario_check_id(stem, c) for c in SCENARIO_CHECKS
        if not c.startswith("translation_") or c == f"translation_{variant}")
    controls = tuple(cid for cid, checker in _control_checkers()
                     if not checker.startswith(ROW_OBLIGATION_PREFIXES) or checker in obligations)
    return obligations, controls


@functools.lru_cache(maxsize=1)
def _control_checkers() -> tuple[tuple[str, str], ...]:
    """(id, checker) of every negative control of the prove machinery (built once: a fraction
    of a second each time)."""
    from ..proofs import collect_controls

    return tuple((c.id, c.checker) for c in collect_controls())


@dataclass(frozen=True)
class _Standing:
    """How a row's required obligations and controls stand in this run's data: ``missing``
    (not run: absent, carried over from an earlier run, or the data not available) and
    ``wrong`` (run, not as expected), each a list of ids; ``held``: how many ran as expected;
    ``stale``: why the proof data are not of this tree (None: they are, or cannot tell)."""

    missing_obligations: tuple[str, ...]
    missing_controls: tuple[str, ...]
    wrong: tuple[str, ...]
    held: int
    total: int
    stale: str | None

    @property
    def missing(self) -> tuple[str, ...]:
        return self.missing_obligations + self.missing_controls

    def text(self) -> str:
        """What the row says of its obligations and controls (for ``why``)."""
        out = [f"{self.held} of {self.total} of its obligations and negative controls ran as "
               "expected" + (f" (not: {', '.join(self.wrong)})" if self.wrong else "")]
        if self.missing_obligations:
            out.append("not in this run: " + ", ".join(self.missing_obligations))
        if self.missing_controls:
            n = len(self.missing_controls)
            out.append(f"{n} negative control{'s' if n != 1 else ''} not in this run ("
                       + (", ".join(self.missing_controls) if n <= 3 else
                          f"{self.missing_controls[0]}, ...; all in report.json's "
                          "summary[].missing") + ")")
        if self.stale:
            out.append(f"proof results not of this tree ({self.stale})")
        return "; ".join(out)


def _standing(doc: Mapping[str, Any], stem: str, variant: str) -> _Standing:
    """The row's ``_Standing`` in report.json's obligations, controls and provenance."""
    obligations, controls = row_requirements(stem, variant)
    ob = doc["obligations"]
    ran = {i["id"]: i for i in ob["items"] if i.get("change") != "not run"} if ob[
        "available"] else {}
    ctl = doc.get("controls") or {"available": False, "items": []}
    checked = {c["id"]: c for c in ctl["items"]} if ctl["available"] else {}
    wrong = tuple(i for i in obligations if i in ran and not ran[i]["as_expected"]) + tuple(
        c for c in controls if c in checked and not checked[c]["ok"])
    missing_ob = tuple(i for i in obligations if i not in ran)
    missing_ctl = tuple(c for c in controls if c not in checked)
    stale = None
    if ob["available"] and "provenance" in doc:
        tree = _proofs_of_this_tree(ob, doc["provenance"])
        stale = tree["detail"] if tree["ok"] is False else None
    total = len(obligations) + len(controls)
    return _Standing(missing_ob, missing_ctl, wrong,
                     total - len(wrong) - len(missing_ob) - len(missing_ctl), total, stale)


def workcell_summary(loaded: Sequence[Scenario], doc: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Section 1: a row per (workcell, variant) with its status, the proved clearance (the
    certificate's lower bound, mm; None unless clear), the least sampled clearance (mm, an upper
    bound on the true minimum), the tolerance in rad, degrees and mm at the farthest point of
    either arm (delta times L, the largest R_base + R_elbow over both arms' parts, the tool tip
    where there is a tool: the most a deviation of delta in every joint moves any point;
    ``tolerance_farthest_point_mm``, also under its former name ``tolerance_tip_mm`` for format
    version 1), the ledger ids it rests on, its verdict and why, ``missing``: the obligations
    and controls it rests on that are not in this run, and ``scope``: ``spec.theorem_scope``,
    what the safety theorem does not cover of the workcell, or None (every workcell today: tools
    and heights are covered; such a row rests on ledger A13 too).

    A found plan's verdict rests on what ran (``row_requirements``): ``ok`` is True ("safe")
    for a plan certified clear with no contract violation whose every required obligation and
    negative control ran in this run's data as expected, the proof data being of this tree;
    False ("FAILED") for a plan not certified clear, a violation, or a required obligation or
    control not as expected; None with verdict "incomplete" when it would be safe but any of
    them is missing (named in ``missing`` and ``why``) or the proof data are of another tree.
    None with "no plan" for "no path" (nothing moves, so nothing is claimed safe). A row that
    would be "safe" but whose workcell the safety theorem does not yet cover (``scope``) is
    "certified" instead: certified clear and checked, not proved (docs/model.md §8, §10)."""
    from ..proofs import ASSUMPTIONS

    ledger = {a.id.split(".")[0]: a.id for a in ASSUMPTIONS}
    ob = doc["obligations"]
    verdicts = {i["id"]: i for i in ob["items"]} if ob["available"] else {}
    rows = []
    for s, entry in zip(loaded, doc["scenarios"]):
        stem = Path(s.source).stem
        reach = tube_lipschitz(s)
        scope = theorem_scope(s)
        for v in entry["variants"]:
            name = v["variant"]
            standing = _standing(doc, stem, name)
            translated = verdicts.get(f"Scenario.{stem}.translation_{name}", {}).get(
                "verdict") == "proved"
            cl = v["clearance"]
            violations = (v["contracts"] or {}).get("violations") or []
            tol = v.get("tolerance_rad")
            needs: tuple[str, ...] = ()
            missing: tuple[str, ...] = ()
            if v["status"] == "found" and cl and cl["clear"] and not violations:
                needs = _SAFETY_ASSUMPTIONS + (() if translated else ("A5",)) + (
                    ("A13",) if _tools_or_heights(s) else ())
                why = ["certified clear in continuous time",
                       f"contracts held ({(v['contracts'] or {}).get('mode', 'not recorded')})"]
                missing = standing.missing
                if standing.wrong:
                    ok, verdict = False, "FAILED"
                elif missing or standing.stale:
                    ok, verdict = None, "incomplete"
                else:
                    ok, verdict = True, "safe" if scope is None else "certified"
            elif v["status"] == "found":
                ok, verdict = False, "FAILED"
                why = ["not certified clear" if not (cl and cl["clear"]) else
                       "certified clear", f"{len(violations)} contract violation(s)"]
            elif v["status"] == "no_path":
                ok = None if not violations else False
                verdict = "no plan" if ok is None else "FAILED"
                witnessed = translated or _held(v["contracts"], "post.optimal")
                needs = _NO_PATH_ASSUMPTIONS + (() if translated else ("A5",)) + (
                    () if witnessed else ("A6",))
                why = [f"no path ({v['reason']})" if v["reason"] else "no path",
                       "its absence checked by a witness" if witnessed else
                       "its absence taken from the search's contract"]
            else:
                ok, verdict, why = False, "FAILED", [f"the plan stopped: {v['reason']}"]
            why.append(standing.text() if ob["available"] else
                       f"its obligations not in this run's proof data ({ob.get('source', 'none')})")
            if verdict == "incomplete":
                why.insert(0, "incomplete: it would be "
                           + ("safe" if scope is None else "certified")
                           + ", but not all it rests on ran in this run")
            if scope is not None:
                why.insert(0, scope)
            found = v["status"] == "found" and tol is not None
            tip = 1000 * reach * tol if found else None
            rows.append({
                "scenario": entry["name"], "variant": name, "status": v["status"],
                "lower_bound_mm": 1000 * cl["lower_bound_m"] if cl and cl["clear"] else None,
                "min_mm": 1000 * cl["min_m"] if cl else None,
                "tolerance_rad": tol if found else None,
                "tolerance_deg": math.degrees(tol) if found else None,
                "tolerance_farthest_point_mm": tip,
                "tolerance_tip_mm": tip,
                "reach_m_per_rad": reach,
                "assumptions": [ledger[a] for a in needs if a in ledger],
                "ok": ok, "verdict": verdict, "scope": scope,
                "missing": list(missing),
                "why": "; ".join(why),
            })
    return rows


def _rows_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    """The verdict's row for section 1: every found plan's verdict rests on what ran. False when
    a row FAILED, None (incomplete) when a row is incomplete, True otherwise."""
    check = "verdict rows rest on what ran"
    rows = doc["summary"]
    failed = [f"{r['scenario']}/{r['variant']}" for r in rows if r["ok"] is False]
    short = [f"{r['scenario']}/{r['variant']}" for r in rows if r["verdict"] == "incomplete"]
    counts: dict[str, int] = {}
    for r in rows:
        counts[r["verdict"]] = counts.get(r["verdict"], 0) + 1
    detail = ", ".join(f"{n} {k}" for k, n in counts.items())
    if failed:
        return _item(check, False, detail + f"; FAILED: {', '.join(failed)}")
    if short:
        n = max(len(r["missing"]) for r in rows)
        return _item(check, None, detail + f"; incomplete: {', '.join(short)} ("
                     + (f"up to {n} of the obligations and negative controls they rest on not "
                        "in this run, named in summary[].missing" if n else
                        "the proof results are not of this tree") + ")")
    return _item(check, True, detail)


def _held(contracts: Mapping[str, Any] | None, condition: str) -> bool:
    """Whether a plan's contract record checked ``condition`` and it held."""
    checks = [c for tr in (contracts or {}).get("triples", []) for c in tr["checks"]
              if c["condition"] == condition]
    return bool(checks) and all(c["ok"] is True for c in checks)


# --- plans ----------------------------------------------------------------------------------------

class _Plans:
    """Plans by (scenario file, variant), each computed once; a contract violation is kept."""

    def __init__(self, contracts: str, progress: _Progress | None = None) -> None:
        self.contracts = contracts
        self.progress = progress or _Progress(None)
        self._done: dict[tuple[str, str, Variant], Any] = {}

    def get(self, s: Scenario, v: Variant) -> Any:
        """The PlanResult, or the CfmpaError that stopped it."""
        from ..runs import plan
        key = (s.source, s.sha256, v)
        if key not in self._done:
            with self.progress.stage(f"plan {s.name}, {v.value}"):
                try:
                    # stop=False: every failed postcondition is recorded, not only the first.
                    self._done[key] = plan(s, v, contracts=self.contracts, seed=0, stop=False)
                except CfmpaError as exc:
                    self._done[key] = exc
        return self._done[key]

    def all(self) -> list[Any]:
        """Every completed plan so far, in the order computed."""
        return [p for p in self._done.values() if not isinstance(p, Exception)]

    def require(self, s: Scenario, v: Variant) -> Any:
        p = self.get(s, v)
        if isinstance(p, Exception):
            raise p
        return p


# --- findings ----------------------------------------------------------------------------------

_FINDING_FNS: dict[str, tuple[Callable[..., Finding], bool, Callable[..., F.Figure]]] = {
    "inconsistency": (inconsistency_finding, True, F.inconsistency_figure),
    "prop8_literal": (prop8_finding, True, F.prop8_figure),
    "is_path_flaw": (early_arrival_finding, True, F.early_arrival_figure),
    "naive_hull": (naive_hull_finding, False, F.naive_hull_figure),
}


def _findings(sdir: Path, loaded: Sequence[Scenario], plans: _Plans,
              figures: dict[str, F.Figure]) -> list[dict[str, Any]]:
    by_path = {Path(s.source).resolve(): s for s in loaded}
    out = []
    for fid, (fn, needs_plans, draw) in _FINDING_FNS.items():
        path = sdir / f"{FINDING_SCENARIOS[fid]}.toml"
        try:
            s = by_path.get(path.resolve()) or load_scenario(path)
            f = fn(s, plans.require) if needs_plans else fn(s)
        except CfmpaError as exc:
            out.append({"id": fid, "available": False, "title": fid, "text": "",
                        "note": f"not available in this run: {exc}", "related": [],
                        "reproduced": None, "data": {}, "figure": None})
            continue
        fig = draw(f"fig-finding-{fid}", f.drawing)
        figures[fig.id] = fig
        out.append({"id": f.id, "available": True, "title": f.title, "text": f.text, "note": "",
                    "related": list(f.related), "reproduced": f.reproduced,
                    "data": jsonable(f.data), "scenario": s.name,
                    "figure": {"id": fig.id, "caption": fig.caption}})
    return out


# --- per scenario --------------------------------------------------------------------------------

def _scenario_entry(s: Scenario, plans: _Plans, figures: dict[str, F.Figure],
                    stages: _Progress | None = None) -> dict[str, Any]:
    from ..runs import plan_json

    results = {v: plans.get(s, v) for v in Variant}
    ok = {v: p for v, p in results.items() if not isinstance(p, Exception)}
    variants: list[dict[str, Any]] = []
    for v, p in results.items():
        if isinstance(p, Exception):
            variants.append({"variant": v.value, "status": "contract_violation",
                             "reason": str(p), "J1": None, "J2": None, "path_length": 0,
                             "path": [], "free_fraction": None, "clearance": None,
                             "contracts": {"violations": [str(p)]}, "timings_s": {},
                             **{k: None for k in _OPTIONAL_PLAN_KEYS}})
            continue
        j = plan_json(p)
        entry_v = {k: j[k] for k in ("variant", "status", "reason", "J1", "J2", "path_length",
                                     "path", "free_fraction", "clearance", "contracts",
                                     "timings_s")}
        # Keys plan.json may carry (added, never renamed): null when this version has none, so
        # report.json keeps one key set.
        entry_v.update({k: j.get(k) for k in _OPTIONAL_PLAN_KEYS})
        variants.append(entry_v)
    checks = contract_rows({v.value: p.contracts for v, p in ok.items()})
    any_plan = next(iter(ok.values()), None)
    grid = any_plan.grid.as_json() if any_plan is not None else None
    entry: dict[str, Any] = {
        "name": s.name, "path": s.source, "sha256": s.sha256, "purpose": s.purpose,
        "parameters": {"dt": s.dt, "left": _arm_json(s.left), "right": _arm_json(s.right)},
        "grid": None if grid is None else {
            **grid, "cells": (grid["N"] + 1) * grid["m"] * grid["n"]},
        "variants": variants, "contract_checks": checks, "figures": [], "tube": None,
    }
    if any_plan is None:
        return entry
    with (stages or _Progress(None)).stage(f"figures and tube of {s.name}"):
        series = _clearance_series(s, ok)
        entry["figures"] = _scenario_figures(s, ok, figures, series)
        entry["tube"] = _tube_entry(s, ok, figures, series)
    return entry


def contract_rows(records: Mapping[str, Mapping[str, Any] | None]) -> list[dict[str, Any]]:
    """The per-condition contract table: one row per (command, part, condition), one cell per
    variant; ``records`` maps a variant to its plan's ``contracts`` record (or None).

    A condition checked by several records (BuiltDR's post.cells: the random sample, then the
    path's cells) is one cell whose counts add up and whose ``ok`` is False if any record failed,
    None if none was checked, else True; ``records`` keeps each record and ``state`` says what
    the report shows: held, FAILED, not checked, n/a (nothing to check) or delegated.
    """
    rows: dict[tuple[str, str, str], dict[str, Any]] = {}
    for variant, rec in records.items():
        for tr in (rec or {}).get("triples", []):
            command = str(tr["title"]).split(",")[0].split(" over")[0]   # BuiltDR | searchoptpath
            for c in tr["checks"]:
                row = rows.setdefault((command, c["part"], c["condition"]), {
                    "command": command, "part": c["part"], "condition": c["condition"],
                    "scope": None, "variants": {}})
                cell = row["variants"].setdefault(variant, {"triple": tr["name"], "records": []})
                cell["records"].append({"count": int(c["count"]), "ok": c["ok"],
                                        "scope": str(c["scope"])})
    out = []
    for row in rows.values():
        for cell in row["variants"].values():
            cell.update(_aggregate(cell["records"]))
        first = next(iter(row["variants"].values()))
        row["scope"] = first["scope"]
        # Key order as report.json prints it: the row's fields, then its cells.
        out.append({k: row[k] for k in ("command", "part", "condition", "scope", "variants")})
    return out


def _aggregate(recs: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    oks = [r["ok"] for r in recs]
    count = sum(r["count"] for r in recs)
    ok = False if False in oks else (None if all(o is None for o in oks) else True)
    if ok is False:
        state = "failed"
    elif ok is None:
        state = "not checked"
    elif count == 0:
        # Nothing examined here: either another check stands for it (pre.dr.spec is BuiltDR's
        # post.cells) or there was nothing to examine (no path): never a green "0 held".
        checked = [r for r in recs if r["ok"] is not None]
        state = "delegated" if all("post.cells" in r["scope"] for r in checked) else "n/a"
    else:
        state = "held"
    return {"count": count, "ok": ok, "state": state,
            "scope": "; ".join(r["scope"] for r in recs)}


def _triples(plans: _Plans) -> list[dict[str, str]]:
    """The distinct Hoare triples the plans' contracts checked, with their printed statements."""
    seen: dict[str, dict[str, str]] = {}
    for p in plans.all():
        for tr in (p.contracts or {}).get("triples", []):
            seen.setdefault(tr["name"], {k: str(tr.get(k, "")) for k in
                                         ("name", "title", "reference", "statement")})
    return [seen[k] for k in sorted(seen)]


def _primary(ok: dict[Variant, Any]) -> Variant:
    """The plan drawn in the workcell and C-space pictures: modified (the paper's), if found."""
    for v in (Variant.MODIFIED, Variant.TIGHT, Variant.ORIGINAL):
        if v in ok and ok[v].search.status is SearchStatus.FOUND:
            return v
    return Variant.MODIFIED if Variant.MODIFIED in ok else next(iter(ok))


def _clearance_series(s: Scenario, ok: dict[Variant, Any]
                      ) -> dict[Variant, tuple[Any, Any]]:
    """The sampled clearance (t, d) along each found plan's executed motion (a picture)."""
    return {v: sample_clearance(s, p.grid, p.search.path) for v, p in ok.items()
            if p.search.status is SearchStatus.FOUND}


def _same_paths(ok: dict[Variant, Any], found: Sequence[Variant]) -> dict[Variant, Variant]:
    """Each found variant whose path equals an earlier one's, mapped to that earlier one."""
    same: dict[Variant, Variant] = {}
    for k, v in enumerate(found):
        for u in found[:k]:
            if u not in same and ok[u].search.path == ok[v].search.path:
                same[v] = u
                break
    return same


def _scenario_figures(s: Scenario, ok: dict[Variant, Any], figures: dict[str, F.Figure],
                      clearance: Mapping[Variant, tuple[Any, Any]]) -> list[dict[str, str]]:
    from ..impl import left_regions_fast  # the plans have loaded the compiled kernels

    slug = _anchor(s.name)
    v0 = _primary(ok)
    p0 = ok[v0]
    g = p0.grid
    cert = p0.certificate
    made = [
        F.workcell_figure(f"fig-{slug}-workcell", s, g, p0.search.path, v0,
                          cert.t_min_s if cert else None, cert.min_clearance_m if cert else None),
        F.cspace_figure(f"fig-{slug}-cspace", s, g, p0.dr, p0.search.path, v0),
    ]
    layer = g.N // 2
    made.append(F.variants_figure(
        f"fig-{slug}-variants", s, g, {v: p.dr for v, p in ok.items()},
        # impl's compiled twin: the same polygons (tested), 20x quicker than left_regions.
        {v: left_regions_fast(s, v, g).links[layer] for v in ok}, layer))
    series, minima, bounds = {}, {}, {}
    # Identical paths are drawn once, and said so.
    same = _same_paths(ok, list(clearance))
    for v, p in ok.items():
        if p.search.status is not SearchStatus.FOUND:
            continue
        series[v] = clearance[v]
        if p.certificate is not None:
            minima[v] = (p.certificate.t_min_s, p.certificate.min_clearance_m)
            # The proved figure is a bound only when every interval was proved clear.
            if p.certificate.clear:
                bounds[v] = p.certificate.lower_bound_m
    if series:
        missing = [v for v in ok if v not in series]
        made.append(F.clearance_figure(f"fig-{slug}-clearance", s, g, series, minima, missing,
                                       same, bounds))
    for f in made:
        figures[f.id] = f
    return [{"id": f.id, "caption": f.caption} for f in made]


def _arm_json(arm: Any) -> dict[str, Any]:
    return jsonable(dataclasses.asdict(arm))


# --- the tolerance tube (docs/model.md §12) ------------------------------------------------------

#: The keys of `cfmpa certify`'s JSON a tube entry keeps (runs.certify_json).
_CERTIFY_KEYS = ("clear", "lower_bound_m", "min_m", "t_s", "tolerance_rad", "intervals")


def _tube_entry(s: Scenario, ok: dict[Variant, Any], figures: dict[str, F.Figure],
                clearance: Mapping[Variant, tuple[Any, Any]]) -> dict[str, Any] | None:
    """Per found plan: its tolerance_rad (plan.json's), the proved clearance c, the tube's margin
    2 L delta, and `cfmpa certify` on its executed motion (traj.csv) for comparison; a figure."""
    from ..runs import certify_json, plan_json

    found = [v for v in clearance if ok[v].certificate is not None]
    if not found:
        return None
    lip = tube_lipschitz(s)
    plans, panels = [], []
    same = _same_paths(ok, found)
    for v in found:
        p = ok[v]
        cert = p.certificate
        tol = plan_json(p)["tolerance_rad"]
        # What `cfmpa certify SCENARIO --traj DIR/traj.csv` computes on the plan's traj.csv
        # (written with 17 digits, so it reads back as these doubles).
        traj = executed_trajectory(s, p.grid, p.search.path)
        again = certify_json(s, traj, certify_trajectory(s, traj))
        plans.append({"variant": v.value, "clear": cert.clear,
                      "lower_bound_m": cert.lower_bound_m, "min_m": cert.min_clearance_m,
                      "t_s": cert.t_min_s, "tolerance_rad": tol, "margin_m": 2.0 * lip * tol,
                      "same_path_as": same[v].value if v in same else None,
                      "certify": {"rows": traj.rows,
                                  **{k: again[k] for k in _CERTIFY_KEYS}}})
        if v in same:
            continue
        names = " = ".join(u.value for u in [v, *(u for u in found if same.get(u) is v)])
        t, d = clearance[v]
        panels.append(F.TubePanel(names, t, d, cert.clear, cert.lower_bound_m, tol,
                                  2.0 * lip * tol, cert.t_min_s, cert.min_clearance_m))
    fig = F.tube_figure(f"fig-{_anchor(s.name)}-tube", s, panels)
    figures[fig.id] = fig
    return {"lipschitz_m_per_rad": lip, "plans": plans,
            "figure": {"id": fig.id, "caption": fig.caption}}


def tube_problems(doc: Mapping[str, Any]) -> list[str]:
    """What disagrees in report.json's tubes: per found plan, plan.json's tolerance_rad against
    the tube's and `cfmpa certify`'s, the proved bound against certify's, the margin against
    2 L delta, and the tolerance lemma's premise c > 2 L delta (a plan not clear: delta = 0)."""
    out = []
    for s in doc["scenarios"]:
        tube = s.get("tube") or {"plans": [], "lipschitz_m_per_rad": None}
        by_variant = {pl["variant"]: pl for pl in tube["plans"]}
        for v in s["variants"]:
            if v["status"] != "found":
                continue
            name = f"{s['name']}/{v['variant']}"
            pl = by_variant.get(v["variant"])
            if pl is None:
                out.append(f"{name}: no tube entry")
                continue
            tol, c, cert = pl["tolerance_rad"], pl["lower_bound_m"], pl["certify"]
            if v.get("tolerance_rad") != tol:
                out.append(f"{name}: plan.json's tolerance_rad {v.get('tolerance_rad')!r}, "
                           f"the tube's {tol!r}")
            if cert["tolerance_rad"] != tol:
                out.append(f"{name}: cfmpa certify gives tolerance_rad {cert['tolerance_rad']!r}, "
                           f"the plan {tol!r}")
            if v["clearance"] is None or v["clearance"]["lower_bound_m"] != c:
                out.append(f"{name}: the tube's proved bound {c!r} is not the plan's")
            if cert["clear"] != pl["clear"] or abs(cert["lower_bound_m"] - c) > BOUND_AGREEMENT_M:
                out.append(f"{name}: cfmpa certify proves {cert['lower_bound_m']!r} m "
                           f"(clear: {cert['clear']}), the plan {c!r} m (clear: {pl['clear']})")
            lip = tube["lipschitz_m_per_rad"]
            if lip is None or not math.isclose(pl["margin_m"], 2.0 * lip * tol, rel_tol=1e-12,
                                               abs_tol=0.0):
                out.append(f"{name}: margin {pl['margin_m']!r} m is not 2 L delta")
            if pl["clear"] and not pl["margin_m"] < c:
                out.append(f"{name}: 2 L delta = {pl['margin_m']!r} m is not below the proved "
                           f"clearance {c!r} m (Tolerance.tube's premise)")
            if not pl["clear"] and tol != 0:
                out.append(f"{name}: not clear, yet tolerance_rad {tol!r}")
    return out


# --- the monitored runs -----------------------------------------------------------------------

def _monitor(loaded: Sequence[Scenario], plans: _Plans,
             figures: dict[str, F.Figure]) -> dict[str, Any]:
    """`cfmpa simulate` then `cfmpa monitor` in process, on each audited workcell's
    MONITOR_VARIANT plan: the tracking log, and the same log with an excursion added. A
    workcell without such a plan (no path found, the plan stopped, not certified clear) has
    an entry saying why instead; ``available`` says whether any workcell was demonstrated."""
    entries = [_monitor_one(s, plans, figures) for s in loaded]
    shown = [e for e in entries if e["available"]]
    note = "" if shown else "not available in this run: " + (
        "; ".join(f"{e['scenario']}: {e['note']}" for e in entries) or "no workcell audited")
    return {"available": bool(shown), "note": note, "workcells": entries}


def monitor_settings(s: Scenario, traj: Any, tol: float
                     ) -> tuple[dict[str, Any], dict[str, Any]] | str:
    """The simulation and the excursion for one workcell's monitored runs, or why there are
    none. MONITOR_SIMULATION as it is when its worst deviation fits in half the tube, else with
    lag, noise and period scaled down until it does: a tracking log then deviates by at most
    noise + lag w_ref at a sample and by (w_robot + w_ref) period / 2 more between samples
    (docs/model.md §12), so it is inside. MONITOR_EXCURSION moved to mid-motion when the motion
    ends before it, and at least 2 tol, so every sample in its window is outside by
    2 tol - tol / 2 > tol."""
    from ..runs import parse_max_speed
    from ..spec import ReferenceSpeeds

    w_ref = float(ReferenceSpeeds.of(traj).top().max())
    w_robot = float(parse_max_speed(None, s, traj).max())
    sim = dict(MONITOR_SIMULATION)
    worst = (sim["noise_rad"] + sim["lag_s"] * w_ref + (w_robot + w_ref) * sim["period_s"] / 2)
    if worst > tol / 2:
        k = tol / 2 / worst
        sim.update(lag_s=sim["lag_s"] * k, noise_rad=sim["noise_rad"] * k,
                   period_s=sim["period_s"] * k)
    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    samples = math.floor((t1 + sim["tail_s"] - t0) / sim["period_s"]) + 2
    if samples > MONITOR_MAX_SAMPLES:
        return (f"the tube of {tol!r} rad would need a log of {samples} samples "
                f"(a sample every {sim['period_s']:.3g} s) to stay inside it, more than the "
                f"report's {MONITOR_MAX_SAMPLES}")
    exc: dict[str, Any] = dict(MONITOR_EXCURSION)
    if not t0 <= exc["t_s"] <= t1 - exc["duration_s"]:
        exc["t_s"] = t0 + max(t1 - t0 - exc["duration_s"], 0.0) / 2
    exc["rad"] = max(exc["rad"], 2 * tol)
    return sim, exc


def _monitor_one(s: Scenario, plans: _Plans, figures: dict[str, F.Figure]) -> dict[str, Any]:
    """One workcell's monitored runs (``_monitor``), or an entry saying why there are none."""
    from ..runs import Excursion, log_csv, monitor_json, monitor_log, simulate_log

    variant = MONITOR_VARIANT

    def none(why: str) -> dict[str, Any]:
        return {"available": False, "scenario": s.name, "note": why}

    p = plans.get(s, variant)
    if isinstance(p, Exception):
        return none(f"the {variant.value} plan stopped ({p}), so there is no plan to monitor")
    if p.search.status is not SearchStatus.FOUND:
        return none(f"no {variant.value} path was found ({p.search.reason}), so there is no "
                    f"plan to monitor")
    traj = executed_trajectory(s, p.grid, p.search.path)
    cert = certify_trajectory(s, traj)          # as `cfmpa monitor` does: its own tube
    if not cert.clear:
        return none(f"the {variant.value} plan is not certified clear, so there is no tube to "
                    f"monitor")
    tol = tolerance_rad(s, cert)
    settings = monitor_settings(s, traj, tol)
    if isinstance(settings, str):
        return none(settings)
    sim, exc_doc = settings
    exc = Excursion(**exc_doc)
    runs, traces = [], []
    for name, excursions in (("tracking", ()), ("excursion", (exc,))):
        t, a = simulate_log(traj, lag=sim["lag_s"], noise=sim["noise_rad"], seed=sim["seed"],
                            excursions=excursions, period=sim["period_s"], tail=sim["tail_s"])
        log = f"{name}.csv"
        res = monitor_log(s, traj, tol, io.StringIO(log_csv(t, a).decode()), source=log)
        mj = monitor_json(s, traj, tol, res, log)
        window = (t >= exc.t_s) & (t <= exc.t_s + exc.duration_s)
        expected: dict[str, Any] = {"status": "inside", "first_outside_t": None,
                                    "first_outside_joint": None, "outside": 0}
        if excursions:
            expected = {"status": "outside", "first_outside_t": float(t[window][0]),
                        "first_outside_joint": exc.joint, "outside": int(window.sum())}
        runs.append({"name": name, "excursion": dict(exc_doc) if excursions else None,
                     "expected": expected,
                     "result": {k: mj[k] for k in _MONITOR_KEYS}})
        # The picture's per-sample deviation (the monitor itself keeps only counts).
        dev = np.abs(a - traj.at(t)).max(axis=1)
        first = None
        if res.first is not None:
            first = (res.first["t_s"], float(dev[int(np.searchsorted(t, res.first["t_s"]))]))
        traces.append(F.MonitorTrace(
            f"{name}: {res.status}, {res.outside} of {res.samples} samples outside",
            t, dev, first))
    fig = F.monitor_figure(f"fig-monitor-{_anchor(s.name)}", f"{s.name}, {variant.value} plan: "
                           f"monitored simulated runs", tol, traces)
    figures[fig.id] = fig
    return {"available": True, "note": "", "scenario": s.name, "variant": variant.value,
            "tolerance_rad": tol, "plan_tolerance_rad": tolerance_rad(s, p.certificate),
            "trajectory": {"rows": traj.rows, "t_start_s": float(traj.t[0]),
                           "t_end_s": float(traj.t[-1])},
            "simulation": sim, "runs": runs,
            "figure": {"id": fig.id, "caption": fig.caption}}


#: The keys of `cfmpa monitor`'s JSON a monitored run keeps (runs.monitor_json).
_MONITOR_KEYS = ("status", "samples", "outside", "outside_in_contact", "max_deviation_rad",
                 "t_first_s", "t_last_s", "first_outside_t", "first_outside_line",
                 "first_outside_joint", "first_outside_deviation_rad", "contact",
                 "tolerance_rad", "max_gap_s", "covered_fraction", "unobserved")


def monitor_problems(mon: Mapping[str, Any]) -> list[str]:
    """What in report.json's monitored run is not as expected: the monitor's tube is the plan's;
    the tracking log inside (its largest deviation within the tolerance); the excursion's log
    outside first at the excursion's first sample, on its joint, and only in its window."""
    out = []
    if mon["tolerance_rad"] != mon["plan_tolerance_rad"]:
        out.append(f"the monitor's tolerance {mon['tolerance_rad']!r} is not the plan's "
                   f"{mon['plan_tolerance_rad']!r}")
    for r in mon["runs"]:
        res, exp = r["result"], r["expected"]
        if res["tolerance_rad"] != mon["tolerance_rad"]:
            out.append(f"{r['name']}: monitored against {res['tolerance_rad']!r} rad")
        for k in ("status", "first_outside_t", "first_outside_joint", "outside"):
            if res[k] != exp[k]:
                out.append(f"{r['name']}: {k} {res[k]!r}, expected {exp[k]!r}")
        if res["status"] == "inside" and res["max_deviation_rad"] > res["tolerance_rad"]:
            out.append(f"{r['name']}: inside, yet a deviation of {res['max_deviation_rad']!r} rad")
    return out


# --- campaign -----------------------------------------------------------------------------------

def _compare(n: int, seed: int, figures: dict[str, F.Figure], recorded: Campaign | None = None,
             folder: str | Path | None = None) -> dict[str, Any]:
    if recorded is not None:
        doc = campaign_json(recorded)
        note = (f"the campaign recorded in {folder} (cfmpa compare --n {recorded.n} --seed "
                f"{recorded.seed} --dt {recorded.dt:g}), read from its records, not run again")
    elif n == 0:
        return {"available": False, "note": "not run for this report (compare_n = 0)"}
    else:
        doc, note = campaign_json(run_campaign(n, seed)), ""
    fig = F.compare_figure("fig-compare", doc)
    rate = F.campaign_rate_figure("fig-compare-rate", doc)
    figures[fig.id], figures[rate.id] = fig, rate
    return {"available": True, "note": note, "text": format_campaign(doc),
            "figure": {"id": fig.id, "caption": fig.caption},
            "rate_figure": {"id": rate.id, "caption": rate.caption}, **doc}


# --- the report's own verdict: the sections' checks ---------------------------------------------

def _verdict(doc: Mapping[str, Any]) -> dict[str, Any]:
    """What the report checks, each ok True / False / None (not available), and the conjunction:
    the checks of SECTIONS, in their order."""
    return verdict_of(doc, SECTIONS)


def _obligations_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    ob = doc["obligations"]
    if not ob["available"]:
        return _item("obligations as expected", None, ob["source"])
    bad = [r["id"] for r in ob["items"] if not r["as_expected"]]
    gaps = ob["missing_ids"] + ob["unexpected_ids"]
    kinds = ob["summary"]["kinds"]
    return _item("obligations as expected", not bad and not gaps,
                 f"{len(ob['items']) - len(bad)} of {len(ob['items'])} ("
                 f"{kinds['theorem']} theorems, {kinds['definitional']} definitional)"
                 + (f"; not as expected: {', '.join(bad)}" if bad else "")
                 + (f"; missing ids: {', '.join(ob['missing_ids'])}"
                    if ob["missing_ids"] else "")
                 + (f"; unexpected ids: {', '.join(ob['unexpected_ids'])}"
                    if ob["unexpected_ids"] else ""))


def _findings_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    fnd = [f for f in doc["findings"] if f["available"]]
    missing = [f["id"] for f in doc["findings"] if not f["available"]]
    not_rep = [f["id"] for f in fnd if not f["reproduced"]]
    return _item("findings reproduced on data", (not not_rep) if fnd else None,
                 f"{len(fnd) - len(not_rep)} of {len(doc['findings'])}"
                 + (f"; not reproduced: {', '.join(not_rep)}" if not_rep else "")
                 + (f"; not available: {', '.join(missing)}" if missing else ""))


def _plans_of(doc: Mapping[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    return [(s["name"], v) for s in doc["scenarios"] for v in s["variants"]]


def _certified_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    found = [(n, v) for n, v in _plans_of(doc) if v["status"] == "found"]
    unclear = [f"{n}/{v['variant']}" for n, v in found
               if not (v["clearance"] and v["clearance"]["clear"])]
    return _item("found paths certified clear", not unclear if found else None,
                 f"{len(found) - len(unclear)} of {len(found)} found paths"
                 + (f"; not clear: {', '.join(unclear)}" if unclear else ""))


def _contracts_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    plans = _plans_of(doc)
    # Off mode still writes a record (checked = 0); only records that checked something count.
    recorded = [(n, v) for n, v in plans if v["contracts"] and v["contracts"].get("checked", 0) > 0]
    violated = [f"{n}/{v['variant']}" for n, v in recorded if v["contracts"].get("violations")]
    # A plan stopped by a violated precondition recorded no count, yet it failed a contract.
    stopped = [f"{n}/{v['variant']}" for n, v in plans if v["status"] == "contract_violation"]
    return _item("contracts hold", (not violated and not stopped) if recorded or stopped else None,
                 f"{len(recorded)} of {len(plans)} plans recorded contracts"
                 + (f"; violated: {', '.join(violated)}" if violated else "")
                 + (f"; stopped by a violation: {', '.join(stopped)}" if stopped else ""))


def _tubes_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    found = [v for _, v in _plans_of(doc) if v["status"] == "found"]
    tubes = [pl for s in doc["scenarios"] for pl in (s["tube"] or {}).get("plans", [])]
    problems = tube_problems(doc)
    return _item("tolerance tubes agree with certify", (not problems) if found else None,
                 f"{len(tubes)} found plans' tubes (c > 2 L delta; tolerance_rad as "
                 f"plan.json and cfmpa certify give it)"
                 + (f"; {'; '.join(problems)}" if problems else ""))


def _selftest_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    st = doc["selftest"]
    if not st["available"]:
        return _item("self-check faults caught (full mode)", None, st["source"])
    missed = [r["fault"] for r in st["rows"] if r.get("caught_full") is False]
    return _item("self-check faults caught (full mode)", not missed,
                 f"{len(st['rows']) - len(missed)} of {len(st['rows'])}"
                 + (f"; missed: {', '.join(map(str, missed))}" if missed else ""))


def _campaign_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    cmp_ = doc["compare"]
    if not cmp_["available"]:
        return _item("campaign checks", None, cmp_["note"])
    bad = {k: v for k, v in cmp_["checks"].items() if v}
    raised = len(cmp_["errors"])
    return _item("campaign checks", not bad and not raised, f"{cmp_['n']} workcells"
                 + (f"; failed: {bad}" if bad else "; all counts 0")
                 + (f"; {raised} workcell(s) raised" if raised else ""))


def _monitor_item(mon: Mapping[str, Any]) -> dict[str, Any]:
    """The row "monitored run as expected": each audited workcell named, with its runs' results
    or why it has none; ok when every demonstrated workcell's runs are as expected, None when no
    workcell was demonstrated."""
    check = "monitored run as expected"
    entries = mon.get("workcells", [])
    if not mon["available"]:
        return _item(check, None, mon["note"])
    parts, bad = [], False
    for e in entries:
        if not e["available"]:
            parts.append(f"{e['scenario']}: none ({e['note']})")
            continue
        problems = monitor_problems(e)
        bad = bad or bool(problems)
        parts.append(f"{e['scenario']} ({e['variant']} plan): "
                     + "; ".join(f"{r['name']}: {r['result']['status']}, "
                                 f"{r['result']['outside']} of {r['result']['samples']} "
                                 f"samples outside" for r in e["runs"])
                     + (f"; not as expected: {'; '.join(problems)}" if problems else ""))
    return _item(check, not bad, " | ".join(parts))


def _proofs_of_this_tree(ob: dict[str, Any], prov: dict[str, Any]) -> dict[str, Any]:
    """Whether the obligation results are of the tree and scenario files this report describes:
    a results.json from another commit, other scenario bytes, or carried-over rows fail it. It
    holds only with a known commit, the same on both sides: where either side has none (an
    install without a build record, a results.json that records none) it is None (unknown),
    saying why."""
    check = "proof results are of this tree"
    if not ob["available"]:
        return _item(check, None, ob["source"])
    if ob["run"] is None:
        if ob["source"].startswith("read from"):
            return _item(check, None, "results.json records no run (commit, scenario hashes)")
        return _item(check, True, "discharged afresh for this report")
    run, problems, unknown = ob["run"], [], []
    mine, theirs = prov["git"].get("commit"), (run.get("git") or {}).get("commit")
    if mine is None:
        unknown.append(f"the report's code has no known commit ({prov['git'].get('note')})")
    if theirs is None:
        unknown.append("results.json records no commit for the prove run")
    if mine is not None and theirs is not None and mine != theirs:
        problems.append(f"proved at commit {theirs}, report at {mine}")
    hashes = run.get("scenarios") or {}
    shown = {".".join(i["id"].split(".")[1:-1]) for i in ob["items"]
             if i["id"].startswith("Scenario.")}
    for s in prov["scenarios"]:
        name = Path(s["path"]).name
        if name in hashes and hashes[name] != s["sha256"]:
            problems.append(f"{name} changed since the prove run")
        elif name not in hashes and Path(name).stem in shown:
            problems.append(f"results.json records no hash for {name}, whose checks are shown")
    if ob["not_run"]:
        problems.append(f"{len(ob['not_run'])} results carried over from an earlier run "
                        f"(e.g. {ob['not_run'][0]})")
    if problems:
        return _item(check, False, "; ".join(problems + unknown))
    if unknown:
        return _item(check, None, "unknown: " + "; ".join(unknown)
                     + " (scenario hashes match), so the results cannot be tied to this tree")
    return _item(check, True,
                 f"commit {theirs}, proved {run.get('date_utc')}, scenario hashes match")


def _item(check: str, ok: bool | None, detail: str) -> dict[str, Any]:
    return {"check": check, "ok": ok, "detail": detail}


# --- helpers ------------------------------------------------------------------------------

def _scenario_paths(scenarios: Sequence[str] | None, sdir: Path) -> list[Path]:
    if scenarios:
        return [Path(p) for p in scenarios]
    found = sorted(sdir.glob("*.toml"))
    if not found:
        raise InputError("scenarios", str(sdir), "holds no *.toml scenario files")
    cwd = Path.cwd().resolve()
    # Relative to the working folder when inside it: the report reads the same on any checkout.
    return [p.resolve().relative_to(cwd) if p.resolve().is_relative_to(cwd) else p for p in found]


def _num(x: Any, digits: int = 3) -> str:
    if x is None:
        return "–"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    return f"{x:.{digits}g}"


def _pct(x: Any, digits: int = 2) -> str:
    return "–" if x is None else f"{100 * x:.{digits}f} %"


def _mm(x: Any, digits: int = 2) -> str:
    return "–" if x is None else f"{1000 * x:.{digits}f} mm"


def _secs(x: Any) -> str:
    return "–" if x is None else f"{x:.3f} s"


def _s3(x: Any) -> str:
    """Seconds under a heading that says "(s)"."""
    return "–" if x is None else f"{x:.3f}"


def _anchor(name: str) -> str:
    return "".join(c if c.isalnum() else "-" for c in str(name)).strip("-").lower() or "x"



# --- the sections, in the order the page shows them (docs/model.md §8) ----------------------------

def _compute_summary(c: _Context) -> dict[str, Any]:
    return {"summary": workcell_summary(c.loaded, c.doc)}


def _compute_provenance(c: _Context) -> dict[str, Any]:
    return {"provenance": provenance(c.argv, c.loaded)}


def _compute_obligations(c: _Context) -> dict[str, Any]:
    proofs = c.proofs()
    return {"obligations": _obligations_part(proofs), "controls": _controls_part(proofs)}


def _compute_assumptions(c: _Context) -> dict[str, Any]:
    return {"assumptions": _assumptions_part(c.proofs())}


def _compute_findings(c: _Context) -> dict[str, Any]:
    with c.stages.stage("findings (their plans listed above)"):
        return {"findings": _findings(c.sdir, c.loaded, c.plans, c.figures)}


def _compute_selftest(c: _Context) -> dict[str, Any]:
    with c.stages.stage("mutation self-check"):
        return {"selftest": load_selftest()}


def _compute_scenarios(c: _Context) -> dict[str, Any]:
    entries = [_scenario_entry(s, c.plans, c.figures, c.stages) for s in c.loaded]
    # The triples of every plan computed so far: the findings' (needed first) and these.
    return {"scenarios": entries, "triples": _triples(c.plans)}


def _compute_monitor(c: _Context) -> dict[str, Any]:
    with c.stages.stage("monitored run"):
        return {"monitor": _monitor(c.loaded, c.plans, c.figures)}


def _compute_compare(c: _Context) -> dict[str, Any]:
    label = ("campaign" + (f" (recorded in {c.campaign})" if c.recorded is not None else
                           f" ({c.compare_n} workcells)" if c.compare_n else " (not run)"))
    with c.stages.stage(label):
        return {"compare": _compare(c.compare_n, c.compare_seed, c.figures, c.recorded,
                                    c.campaign)}


def _this_tree_item(doc: Mapping[str, Any]) -> dict[str, Any]:
    return _proofs_of_this_tree(doc["obligations"], doc["provenance"])


#: The report's parts, in the order the page shows them; each one's checks are its rows of the
#: verdict, in this order too. The proofs' sections are deferred: computed after the plans,
#: pictures and campaign, which do not need them (`cfmpa prove --audit` overlaps the two).
SECTIONS: tuple[Section, ...] = (
    Section("summary", "Verdict per workcell", _compute_summary, "section_summary.html",
            needs=("scenarios", "obligations", "controls", "provenance"), checks=(_rows_item,),
            contents=('<a href="#workcells">Verdict per workcell</a>',)),
    Section("provenance", "Provenance and what this run checked", _compute_provenance,
            "section_provenance.html"),
    Section("obligations", "Summary of obligations, negative controls and obligations",
            _compute_obligations, "section_obligations.html", more=("controls",), deferred=True,
            checks=(_obligations_item, _controls_item, _this_tree_item), headings=2,
            contents=('<a href="#summary">Summary of obligations</a> and '
                      '<a href="#controls">negative controls</a>',
                      '<a href="#obligations">Obligations</a>')),
    Section("assumptions", "Assumptions ledger", _compute_assumptions,
            "section_assumptions.html", deferred=True),
    Section("findings", "Findings about the paper", _compute_findings, "section_findings.html",
            checks=(_findings_item,), finish=_relate),
    Section("selftest", "Mutation self-check", _compute_selftest, "section_selftest.html",
            checks=(_selftest_item,)),
    Section("scenarios", "Scenarios", _compute_scenarios, "section_scenarios.html",
            more=("triples",), needs=("findings",),
            checks=(_certified_item, _contracts_item, _tubes_item),
            contents=('<a href="#scenarios">Scenarios</a>: {% for s in doc.scenarios %}'
                      '<a href="#scenario-{{ s.name|anchor }}">{{ s.name }}</a>'
                      '{% if not loop.last %}, {% endif %}{% endfor %}',)),
    Section("monitor", "Monitored execution", _compute_monitor, "section_monitor.html",
            checks=(lambda doc: _monitor_item(doc["monitor"]),)),
    Section("compare", "Comparison campaign", _compute_compare, "section_compare.html",
            checks=(_campaign_item,)),
)
