"""`cfmpa selftest --code`: seeded mutations of the source, and what catches each.

Each mutant is one edit of a copy of the installed packages (impl's code: the D_R builder, the
regions, the search). The copy is laid out as the installed ``cfmpa`` package in a temporary
folder and run in fresh processes that import it (``PYTHONPATH``), never the original: ``cfmpa
prove`` in full, the contracts (``cfmpa plan``'s modes on every bundled scenario and variant) and,
in a checkout, the tests of impl and runs. A mutant is *caught* by a check when that check fails
on it; every mutant must be caught by ``cfmpa prove`` (docs/model.md §7.3).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

from ..errors import CfmpaError, InputError

__all__ = ["CODE_CHECKS", "CODE_MUTANTS", "CodeMutant", "CodeRow", "code_mutation_table",
           "code_mutation_rows", "imports_copy", "mutated_copy", "run_code_selftest"]


@dataclass(frozen=True)
class CodeMutant:
    """One seeded source edit: in package file ``file`` (e.g. ``impl/_regions.py``), each
    ``old`` text, which must occur exactly once, becomes its ``new`` text."""

    name: str
    what: str
    file: str
    edits: tuple[tuple[str, str], ...]


CODE_MUTANTS: tuple[CodeMutant, ...] = (
    CodeMutant("rest_layer_free", "the fast BuiltDR leaves the rest layer free",
               "impl/_fast_builtdr.py",
               (("    clock.lap(\"other\")\n    return P\n",
                 "    clock.lap(\"other\")\n    P[-1] = 0  # mutant\n    return P\n"),)),
    CodeMutant("margin_halved", "the regions grown by half the margin the lemma needs",
               "impl/_regions.py",
               (("    return t1, t2, margin_scale * sweep_margin(arm, link, g, moving)",
                 "    return t1, t2, 0.5 * margin_scale * sweep_margin(arm, link, g, moving)"),)),
    CodeMutant("lattice_coarsened", "the regions sampled at twice the spacing their margin is "
               "computed for", "impl/_regions.py",
               (("        i_lo, i_hi = lattice_range(box[q][0], box[q][1], anchor[q], g[q])\n"
                 "        axes.append(anchor[q] + np.arange(i_lo, i_hi + 1) * g[q])",
                 "        i_lo, i_hi = lattice_range(box[q][0], box[q][1], anchor[q], 2 * g[q])\n"
                 "        axes.append(anchor[q] + np.arange(i_lo, i_hi + 1) * (2 * g[q]))"),)),
    CodeMutant("box_sign_flipped", "the principal's box per layer swept backwards (mirrored "
               "about theta_L(k dt))", "impl/_builtdr.py",
               (("        box = left_box(s, v, k)\n        anchor = left_angles(s, k * s.dt)\n",
                 "        anchor = left_angles(s, k * s.dt)\n"
                 "        box = tuple((2 * a - hi, 2 * a - lo)\n"
                 "                    for (lo, hi), a in zip(left_box(s, v, k), anchor))\n"),)),
    CodeMutant("search_skips_rest_layer", "both searches take the rest layer as free",
               "impl/_search.py",
               (("    free = FreeLayers(dr)\n",
                 "    free = FreeLayers(np.concatenate([np.asarray(dr)[:N],  # mutant\n"
                 "                                      np.zeros_like(np.asarray(dr)[N:])]))\n"),)),
    CodeMutant("right_regions_turned_backwards", "the fast right regions turned by -t_i "
               "instead of t_i", "impl/_fast_regions.py",
               (("        ci, si, nsi = c[i], s[i], -s[i]\n",
                 "        ci, si, nsi = c[i], -s[i], s[i]\n"),)),
    CodeMutant("layer_count_off_by_one", "the principal's regions for N - 1 layers, not N",
               "impl/_builtdr.py",
               (("    for k in range(g.N):\n        box = left_box(s, v, k)\n",
                 "    for k in range(g.N - 1):\n        box = left_box(s, v, k)\n"),)),
    # --- the witness checker's conditions (docs/model.md §7.3, §11) ---
    CodeMutant("witness_edge_loosened", "the witness checker's edge bound loosened by one "
               "(label[s'] <= label[s] + cost + 1)", "spec/_witness.py",
               (("    return target_key <= bound\n", "    return target_key <= bound + 1\n"),)),
    CodeMutant("witness_goal_inequality", "the witness checker's goal comparison turned into an "
               "inequality (the path's cost >= the least goal label)", "spec/_witness.py",
               (("    return (cost[0] == least[0]) & (cost[1] == least[1])\n",
                 "    return (cost[0] >= least[0]) & (cost[1] >= least[1])\n"),)),
    # --- faults in what the safety theorem reads (docs/model.md §7.3, §10) ---
    CodeMutant("modified_box_half_step", "the modified variant's layer box covers half its time "
               "step (a + s omega dt / 2)", "spec/_grid.py",
               (("    end = a + if_then(up, 1.0, -1.0) * step\n",
                 "    end = a + if_then(up, 1.0, -1.0) * (0.5 * step)\n"),)),
    CodeMutant("lattice_snap_widened", "impl.lattice_range snaps box ends within 1000 SNAP g of "
               "a lattice point (the margin pays for SNAP g)", "impl/_regions.py",
               (("        i_lo = floor_of((lo - anchor) / g + SNAP)\n"
                 "        i_hi = ceil_of((hi - anchor) / g - SNAP)\n",
                 "        i_lo = floor_of((lo - anchor) / g + 1000 * SNAP)\n"
                 "        i_hi = ceil_of((hi - anchor) / g - 1000 * SNAP)\n"),)),
    CodeMutant("composition_region_strengthened", "the compositions' region hypothesis "
               "strengthened: a link of the principal lies in layer k's region whatever its box",
               "proofs/_obl_safety.py",
               (("         z3.And([z3.Implies(z3.And(0 <= k, k < at.d.N, in_box(theta_l, box_k)),\n",
                 "         z3.And([z3.Implies(z3.And(0 <= k, k < at.d.N),\n"),)),
    # --- the certificate's, the tube's and the ball gap's constants (docs/model.md §7.3)
    # (proofs/_obl_constants.py; each caught by its obligation under --repin) ---
    CodeMutant("link_speed_halved", "the certificate's link speed bound halved "
     "(0.5 (|w1| R_base + |w2| R_elbow))", "spec/_certificate.py",
     (("    return w[:, 0:1] * r_base[None, :] + w[:, 1:2] * r_elbow[None, :]\n",
       "    return 0.5 * (w[:, 0:1] * r_base[None, :] + w[:, 1:2] * r_elbow[None, :])\n"),)),
    CodeMutant("interval_lipschitz_halved", "the certificate's interval bound with half its Lipschitz "
     "term ((d0 + d1 - L (t1 - t0) / 2) / 2)", "spec/_certificate.py",
     (("    return (d0 + d1 - lip * length) / 2.0\n",
       "    return (d0 + d1 - 0.5 * lip * length) / 2.0\n"),)),
    CodeMutant("pair_lipschitz_halved", "the distance's Lipschitz constant of a link pair halved "
     "((v_a + v_b) / 2)", "spec/_certificate.py",
     (("    return v_left + v_right\n", "    return 0.5 * (v_left + v_right)\n"),)),
    CodeMutant("reach_without_cap", "the forearm's reach forgets the w/2 cap past the tip "
     "(hypot(l2, w/2))", "spec/_kinematics.py",
     (("    far = hypot_of(arm.links[1] + r, r)\n", "    far = hypot_of(arm.links[1], r)\n"),)),
    CodeMutant("tube_factor_halved", "the tube's margin 2 L delta halved to L delta",
     "spec/_trajectory.py",
     (("    two_l = 2.0 * tube_lipschitz(s)\n", "    two_l = 1.0 * tube_lipschitz(s)\n"),)),
    CodeMutant("tolerance_early_return_loosened", "the tube's radius computed for any positive clearance "
     "(c > 0 instead of c > EPS: a negative radius for c <= EPS)", "spec/_trajectory.py",
     (("    if not cert.clear or cert.lower_bound_m <= EPS:\n",
       "    if not cert.clear or cert.lower_bound_m <= 0.0:\n"),)),
    CodeMutant("tube_lipschitz_left_only", "the tube's L taken over the principal's links only",
     "spec/_trajectory.py",
     (("    return max(sum(reach(arm, link)) for arm in (s.left, s.right) for link in parts(arm))\n",
       "    return max(sum(reach(arm, link)) for arm in (s.left,) for link in parts(arm))\n"),)),
    CodeMutant("gap_without_norm", "the ball-arithmetic gap not divided by |n|", "spec/_exact.py",
     (("    return (lo_b - hi_a) / sqrt_of(nx * nx + ny * ny)\n",
       "    return lo_b - hi_a\n"),)),
    CodeMutant("gap_sign_flipped", "the ball-arithmetic gap with its sign flipped ((hi_a - lo_b) / |n|)",
     "spec/_exact.py",
     (("    return (lo_b - hi_a) / sqrt_of(nx * nx + ny * ny)\n",
       "    return (hi_a - lo_b) / sqrt_of(nx * nx + ny * ny)\n"),)),
    CodeMutant("gap_projection_min", "the upper projection end of A taken as the least, not the greatest",
     "spec/_exact.py",
     (("    hi_a = functools.reduce(max_of, (_upper(nx * x + ny * y) for x, y in a))\n",
       "    hi_a = functools.reduce(min_of, (_upper(nx * x + ny * y) for x, y in a))\n"),)),
    CodeMutant("eps_zero", "BuiltDR frees a cell at any positive float distance (EPS = 0)",
               "spec/_grid.py", (("\nEPS = 1e-9\n", "\nEPS = 0.0\n"),)),
    # --- the wiring: which segment, pieces, label or kind a verdict reads (docs/model.md §6.4,
    # §7.3, §10-§12; proofs/_obl_wiring.py, proofs/_controls_wiring.py) ---
    CodeMutant("certificate_previous_segment_speed", "the certificate takes the previous path "
               "segment's speed for a time piece (Certificate.wiring's right_rate refuted; "
               "Control.certificate.moving_contact certified clear)", "spec/_certificate.py",
               (("        wr = np.where(seg[:, None] >= 0, steps[np.maximum(seg, 0)], 0.0)\n",
                 "        wr = np.where(seg[:, None] >= 0, steps[np.maximum(seg - 1, 0)], 0.0)\n"),)),
    CodeMutant("trajectory_previous_row_speed", "a trajectory's certificate takes the previous "
               "row's speeds for a piece (Certificate.wiring's trajectory VC refuted)",
               "spec/_trajectory.py",
               (("                np.maximum(seg - self.offset, 0)]\n",
                 "                np.maximum(seg - self.offset - 1, 0)]\n"),)),
    CodeMutant("monitor_gap_slice_short", "the monitor's speed over a gap leaves out the gap's "
               "last trajectory piece (Monitor.reference_speeds refuted; "
               "Control.monitor.gap_last_piece covered)", "spec/_trajectory.py",
               (("            out[g] = self.per_piece[lo[g]:hi[g] + 1].max(axis=0)\n",
                 "            out[g] = self.per_piece[lo[g]:hi[g]].max(axis=0)\n"),)),
    CodeMutant("witness_start_or_and", "the witness checker's start test with its or made and "
               "(Witness.labels_sound's labels.base refuted; Control.witness.raised_start "
               "accepted)", "spec/_witness.py",
               (("    return (j1 != 0) | (j2 != 0)\n", "    return (j1 != 0) & (j2 != 0)\n"),)),
    CodeMutant("control_error_counted_rejected", "a control that cannot build its input counted "
               "as rejected (Control.harness.error_is_not_a_pass)", "proofs/_controls.py",
               (("        outcome, detail = \"error\", f\"{type(exc).__name__}: {exc}\"\n",
                 "        outcome, detail = \"rejected\", f\"{type(exc).__name__}: {exc}\"\n"),)),
    CodeMutant("theorem_made_definitional", "a theorem declared definitional "
               "(Control.accept.kinds rejected, Control.kinds.theorem_moved not made; its kind, "
               "pinned in obligations.lock, is not what --repin may change either)",
               "proofs/_obl_safety.py",
               (("        summary=(\"A pair of regions the planner frees, its rounded distance",
                 "        definitional=\"a definition restated\",\n"
                 "        summary=(\"A pair of regions the planner frees, its rounded distance"),)),
    CodeMutant("exact_rest_layer_skipped", "the exact re-decision stops a step short, the path's "
               "rest-layer cell never re-decided (Control.exact.rest_layer_contact proved free; "
               "Scenario.*.translation_*'s exact.coverage)", "spec/_exact.py",
               (("    for k in range(max(len(cells) - 1, N) + 1):\n",
                 "    for k in range(max(len(cells) - 1, N)):\n"),)),
    CodeMutant("exact_tool_square_corner_dropped", "the exact re-decision grows a tool's vertices "
               "by three corners of the square, not four (Exact.gap_formula's tool_points "
               "refuted)", "spec/_exact.py",
               (("    steps = [(-grow, -grow), (grow, -grow), (grow, grow), (-grow, grow)]\n",
                 "    steps = [(-grow, -grow), (grow, -grow), (grow, grow)]\n"),)),
    CodeMutant("loader_spacing_bound_raised", "the loader's exact spacing bound raised above the "
               "157/50 the safety proofs assume (Control.loader.spacing_above_bound loaded)",
               "spec/_scenario.py",
               (("\n_G_MAX = MAX_SPACING\n", "\n_G_MAX = MAX_SPACING + Fraction(1, 100)\n"),)),
    # --- tools and heights under proof (docs/model.md §7.3, §10; proofs/_obl_tools.py: each
    # caught by its obligation under --repin) ---
    CodeMutant("travel_time_min", "the travel time Tf from the quickest joint (max made min): "
               "the principal's slower joint overshoots its boxes (Safety.*.principal_in_layer_box's "
               "travel refuted, the compositions' Tf read from spec.exact_tf on terms)",
               "spec/_counts.py",
               (("    return max(abs(_read(goal[q], reading) - _read(start[q], reading))",
                 "    return min(abs(_read(goal[q], reading) - _read(start[q], reading))"),)),
    CodeMutant("spacing_bound_above_pi", "the spacing bound the loader and the proofs read "
               "raised to 16/5 rad, past pi where A3's facts fail (Safety.*.composition's "
               "spacing_below_pi refuted)", "spec/_counts.py",
               (("MAX_SPACING = Fraction(157, 50)\n", "MAX_SPACING = Fraction(16, 5)\n"),)),
    CodeMutant("heights_compared_strictly", "the height test compares with < where <= is meant "
               "(touching intervals called disjoint: Safety.height_rule refuted)",
               "spec/_kinematics.py",
               (("    return a[0] <= b[1] and b[0] <= a[1]\n",
                 "    return a[0] < b[1] and b[0] < a[1]\n"),)),
    CodeMutant("height_gap_far_ends", "the height gap measured between the intervals' far ends "
               "(a gap larger than the true one: Certificate.height_gap's gap_vertical refuted)",
               "spec/_kinematics.py",
               (("    return max(0.0, a[0] - b[1], b[0] - a[1])\n",
                 "    return max(0.0, a[1] - b[0], b[1] - a[0])\n"),)),
    CodeMutant("tool_vertex_left_out", "the tool's last vertex left out of its region's points "
               "(Safety.tool_region's tool_points refuted)", "impl/_kinematics.py",
               (("    local = np.asarray(arm.tool.polygon, dtype=float)  ",
                 "    local = np.asarray(arm.tool.polygon[:-1], dtype=float)  "),)),
    CodeMutant("tool_margin_nearest_vertex", "the tool's reach, and so its margin, from its "
               "nearest vertex instead of its farthest (Safety.tool_region's far_vertex refuted)",
               "impl/_kinematics.py",
               (("        far_tool = max(float(np.hypot(l2 + x, y)) for x, y in arm.tool.polygon)\n",
                 "        far_tool = min(float(np.hypot(l2 + x, y)) for x, y in arm.tool.polygon)\n"),)),
    CodeMutant("tool_in_link1_frame", "the tool's polygon laid along link 1 (its axes turned by "
               "theta1 only) at the wrist (Safety.tool_region's tool_points refuted)",
               "impl/_kinematics.py",
               (("    wrist = elbow + arm.links[1] * along\n",
                 "    wrist = elbow + arm.links[1] * along\n"
                 "    along = np.stack([np.cos(t1), np.sin(t1)], axis=-1)  # mutant\n"
                 "    normal = np.stack([-along[..., 1], along[..., 0]], axis=-1)\n"),)),
    CodeMutant("tube_lipschitz_without_tool", "the tube's L over the links only, the tools' reach "
               "left out (Tolerance.tube_factor's lipschitz_tool refuted)", "spec/_trajectory.py",
               (("    return max(sum(reach(arm, link)) for arm in (s.left, s.right) for link in "
                 "parts(arm))\n",
                 "    return max(sum(reach(arm, link)) for arm in (s.left, s.right) for link in "
                 "(0, 1))\n"),)),
    CodeMutant("tool_speed_from_forearm", "the certificate's speed bound for a tool from the "
               "forearm's reach (Certificate.lipschitz's speed_tool refuted)",
               "spec/_certificate.py",
               (("    per_link = [reach(arm, link) for link in parts(arm)]\n",
                 "    per_link = [reach(arm, min(link, 1)) for link in parts(arm)]\n"),)),
)

#: The checks a mutant is run through, in this order.
CODE_CHECKS: tuple[str, ...] = ("prove", "contracts", "tests")

#: The packages copied, as (import name, folder under the copy's ``cfmpa``).
_PACKAGES = (("cfmpa", ""), ("cfmpa.spec", "spec"), ("cfmpa.impl", "impl"),
             ("cfmpa.proofs", "proofs"), ("cfmpa.runs", "runs"), ("cfmpa.report", "report"),
             ("cfmpa.scenarios", "scenarios"))

#: The tests that exercise impl and the checked runs (a checkout's ``tests/``).
TEST_FOLDERS = ("impl", "runs")

#: Run in the copy: every bundled scenario and variant planned in both contract modes; prints
#: one JSON line of {"mode": [the plans with a violation, each "scenario/variant: condition"]}.
_CONTRACTS_SCRIPT = """
import json, sys
from cfmpa.runs import plan
from cfmpa.scenarios import BUNDLED_DIR, bundled_names
from cfmpa.spec import Variant, load_scenario
out = {}
for mode in ("sampled", "full"):
    bad = []
    for name in bundled_names():
        s = load_scenario(BUNDLED_DIR / f"{name}.toml")
        for v in Variant:
            try:
                r = plan(s, v, contracts=mode, seed=0, stop=False)
                found = [str(x).splitlines()[0] for x in r.violations]
            except Exception as e:  # a failed precondition stops the run: caught as well
                found = [f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}"]
            if found:
                bad.append(f"{name}/{v.value}: {found[0]}")
    out[mode] = bad
print(json.dumps(out))
"""


@dataclass(frozen=True)
class CodeRow:
    """What each check said of one mutant: per check, caught (True), passed (False) or not run
    (None), with a one-line reason; and the seconds it took."""

    mutant: str
    what: str
    caught: dict[str, bool | None]
    detail: dict[str, str]
    seconds: dict[str, float]


def _package_dir(name: str) -> Path:
    import importlib

    return Path(importlib.import_module(name).__file__).parent   # type: ignore[arg-type]


def mutated_copy(mutant: CodeMutant | None, dest: Path) -> Path:
    """The installed packages copied to ``dest``/cfmpa (the layout ``import cfmpa`` finds with
    ``dest`` on the path), with ``mutant``'s edits made; returns ``dest``. Raises InputError
    when an edit's text is not in the file exactly once (the mutant could not be made)."""
    for name, sub in _PACKAGES:
        src = _package_dir(name)
        to = dest / "cfmpa" / sub
        to.mkdir(parents=True, exist_ok=True)
        for f in sorted(src.iterdir()):
            if f.is_file() and f.suffix in (".py", ".toml", ".lock", ".json", ".html", ".typed"):
                shutil.copy2(f, to / f.name)
    if mutant is not None:
        target = dest / "cfmpa" / mutant.file
        text = target.read_text()
        for old, new in mutant.edits:
            count = text.count(old)
            if count != 1:
                raise InputError("mutant", mutant.name,
                                 f"its edit of {mutant.file} matches {count} times, not once: "
                                 f"{old.strip().splitlines()[0]!r}")
            text = text.replace(old, new)
        target.write_text(text)
    return dest


def _env(copy: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(copy)] + [p for p in env.get("PYTHONPATH", "").split(
        os.pathsep) if p])
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    env.pop("NUMBA_CACHE_DIR", None)
    return env


#: The interpreter, with -P: the working folder is not put first on the path, so a process
#: started in a checkout imports the copy, not the checkout's cfmpa/ folder.
_PYTHON = (sys.executable, "-P")


def imports_copy(copy: Path, cwd: Path) -> bool:
    """Whether a process started as the checks start theirs (in ``cwd``) imports the copy's
    cfmpa and cfmpa.impl."""
    code, text = _run([*_PYTHON, "-c", "import cfmpa, cfmpa.impl; "
                       "print(cfmpa.__file__); print(cfmpa.impl.__file__)"], copy, cwd, 120)
    files = [Path(x) for x in text.split()]
    return code == 0 and len(files) == 2 and all(f.is_relative_to(copy) for f in files)


def _run(cmd: Sequence[str], copy: Path, cwd: Path, timeout_s: float) -> tuple[int, str]:
    try:
        p = subprocess.run(list(cmd), cwd=cwd, env=_env(copy), capture_output=True, text=True,
                           timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return -1, f"timed out after {timeout_s:.0f} s"
    return p.returncode, p.stdout + p.stderr


def _check_prove(copy: Path, work: Path, only: Sequence[str] = ()) -> tuple[bool | None, str]:
    out = work / "proofs"
    select = [a for i in only for a in ("--only", i)]
    # --repin (in the copy, on the copy's own lock): a mutant is caught by a failing obligation
    # or negative control, never by a changed statement hash that a review would accept.
    code, text = _run([*_PYTHON, "-m", "cfmpa", "prove", "--repin", "--out", str(out), *select],
                      copy, work, 1800)
    if code not in (0, 1):
        return None, f"cfmpa prove exited {code}: {text.strip().splitlines()[-1:]}"
    failed = []
    try:
        doc = json.loads((out / "results.json").read_text())
        failed = [o["id"] for o in doc["obligations"] if not o.get("as_expected", True)]
        failed += [c["id"] for c in doc.get("controls", []) if not c.get("ok", True)]
        failed += [f"kind of {k['id']}" for k in doc.get("pins", {}).get("kind_mismatch", [])]
    except (OSError, ValueError, KeyError):
        pass
    if code == 0:
        return False, "every verdict as expected"
    if not failed:
        return True, "exit 1, with every verdict and control as expected (an id missing or extra)"
    return True, (f"exit 1 under --repin; {len(failed)} obligation(s) or control(s) not as "
                  "expected: " + ", ".join(failed[:4]) + (", ..." if len(failed) > 4 else ""))


def _check_contracts(copy: Path, work: Path) -> tuple[bool | None, str]:
    code, text = _run([*_PYTHON, "-c", _CONTRACTS_SCRIPT], copy, work, 1800)
    try:
        found = json.loads(text.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return None, f"the contract runs did not finish (exit {code}): {text.strip()[-200:]}"
    parts = [f"{mode}: {len(bad)} of 15 plans" + (f" (first {bad[0]})" if bad else "")
             for mode, bad in found.items()]
    return bool(found.get("sampled") or found.get("full")), "; ".join(parts)


def _check_tests(copy: Path, work: Path, tests_dir: Path | None) -> tuple[bool | None, str]:
    if tests_dir is None:
        return None, "not run: no tests/ folder (not a checkout)"
    folders = [str(tests_dir / f) for f in TEST_FOLDERS]
    # Started in the work folder, not the checkout (whose cfmpa/ folder would be found first).
    code, text = _run([*_PYTHON, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider",
                       "--rootdir", str(tests_dir.parent), *folders], copy, work, 3600)
    lines = text.strip().splitlines()
    failing = [ln for ln in lines if ln.startswith(("FAILED", "ERROR"))]
    if code == 0:
        return False, lines[-1] if lines else "passed"
    if code == 1 and failing:
        return True, failing[0][:160]
    return None, f"pytest exited {code}: {lines[-1] if lines else ''}"


def _tests_dir() -> Path | None:
    from ..gitstate import repo_root

    root = repo_root()
    t = None if root is None else Path(root) / "tests"
    return t if t is not None and (t / "impl").is_dir() else None


def _chosen(names: Sequence[str] | None, checks: Sequence[str]) -> list[CodeMutant]:
    known = {m.name: m for m in CODE_MUTANTS}
    for n in names or ():
        if n not in known:
            raise InputError("--mutant", n, f"is not one of {', '.join(known)}")
    for c in checks:
        if c not in CODE_CHECKS:
            raise InputError("--checks", c, f"is not one of {', '.join(CODE_CHECKS)}")
    return [known[n] for n in names] if names else list(CODE_MUTANTS)


def code_mutation_rows(names: Sequence[str] | None = None, *,
                       checks: Sequence[str] = CODE_CHECKS, prove_only: Sequence[str] = (),
                       stream: Any = None) -> tuple[CodeRow, ...]:
    """Run each mutant (all, or those named) through ``checks``; one row each, in order.
    ``prove_only`` runs cfmpa prove on those obligations alone (``--only``), for a quick look."""
    chosen = _chosen(names, checks)
    tests_dir = _tests_dir()
    rows = []
    for m in chosen:
        caught: dict[str, bool | None] = {}
        detail: dict[str, str] = {}
        seconds: dict[str, float] = {}
        with tempfile.TemporaryDirectory(prefix=f"cfmpa-mutant-{m.name}-") as tmp:
            copy = mutated_copy(m, Path(tmp) / "src")
            work = Path(tmp) / "work"
            work.mkdir()
            if not imports_copy(copy, work):
                raise CfmpaError(f"a process started in {work} does not import the copy in "
                                 f"{copy}: the mutant would not be what the checks run")
            for c in checks:
                t0 = time.perf_counter()
                if c == "prove":
                    caught[c], detail[c] = _check_prove(copy, work, prove_only)
                elif c == "contracts":
                    caught[c], detail[c] = _check_contracts(copy, work)
                else:
                    caught[c], detail[c] = _check_tests(copy, work, tests_dir)
                seconds[c] = round(time.perf_counter() - t0, 1)
                if stream is not None:
                    word = {True: "caught", False: "NOT caught", None: "undecided"}[caught[c]]
                    print(f"  {m.name}: {c}: {word} ({seconds[c]} s) {detail[c]}", file=stream,
                          flush=True)
        rows.append(CodeRow(m.name, m.what, caught, detail, seconds))
    return tuple(rows)


def code_mutation_table(rows: Sequence[CodeRow]) -> str:
    """The mutation table: one line per mutant, caught / not caught / not run per check."""
    checks = [c for c in CODE_CHECKS if any(c in r.caught for r in rows)]
    word = {True: "caught", False: "MISSED", None: "-"}
    width = max([len(r.mutant) for r in rows] + [6])
    out = [f"{'mutant':<{width}}  " + "  ".join(f"{c:<9}" for c in checks),
           "-" * (width + 11 * len(checks))]
    for r in rows:
        out.append(f"{r.mutant:<{width}}  " + "  ".join(
            f"{word[r.caught[c]] if c in r.caught else '':<9}" for c in checks))
    if "prove" in checks:
        score = sum(1 for r in rows if r.caught.get("prove"))
        out.append(f"cfmpa prove caught {score} of {len(rows)} mutants")
    return "\n".join(out)


def run_code_selftest(names: Sequence[str] | None = None, *,
                      checks: Sequence[str] = CODE_CHECKS, prove_only: Sequence[str] = (),
                      json_out: str | None = None, stdout: TextIO | None = None) -> int:
    """`cfmpa selftest --code`: the table on ``stdout`` (default sys.stdout), and JSON if asked;
    0 iff cfmpa prove caught every mutant run (1 otherwise)."""
    from ..files import JsonStyle, dumps_json, write_bytes_atomic

    so = sys.stdout if stdout is None else stdout
    _chosen(names, checks)
    print(f"seeded source mutations of a copy of the packages; checks: {', '.join(checks)}",
          file=so, flush=True)
    if prove_only:
        print(f"cfmpa prove on {', '.join(prove_only)} only (not the whole run)", file=so)
    rows = code_mutation_rows(names, checks=checks, prove_only=prove_only, stream=so)
    print(code_mutation_table(rows), file=so)
    if json_out is not None:
        doc = {"checks": list(checks), "prove_only": list(prove_only),
               "mutants": [{"mutant": r.mutant, "what": r.what, "caught": r.caught,
                            "detail": r.detail, "seconds": r.seconds} for r in rows]}
        write_bytes_atomic(json_out, dumps_json(doc, JsonStyle.LOCK).encode())
    if "prove" not in checks:
        return 0
    missed = [r.mutant for r in rows if not r.caught.get("prove")]
    if missed:
        print(f"NOT CAUGHT by cfmpa prove: {', '.join(missed)}", file=so)
        return 1
    return 0
