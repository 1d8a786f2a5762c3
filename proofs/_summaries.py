"""Each obligation in one plain sentence, for a reader who does not read the statements.

The audit report (docs/model.md §8) shows a summary on every obligation's card, with the full
statement folded out below it. A summary says what the obligation establishes in the paper's and
the robot's words: at most ``MAX_CHARS`` characters, no module, function or ledger names (the
statement has those). ``SUMMARIES`` maps an obligation id, or a pattern whose ``*`` stands for
one dot-free part of the id (the workcell of a per-scenario check), to its sentence;
``{workcell}`` in a sentence is filled with that part. ``summary_problems`` is the check the
tests run over every registered obligation.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping

__all__ = ["FORBIDDEN", "MAX_CHARS", "SUMMARIES", "obligation_summary", "summary_problems"]

#: The longest summary allowed (a card's one line, two at most).
MAX_CHARS = 240

#: What a plain summary must not contain, each with what it would be: the names belong in the
#: statement, not in the sentence a reviewer reads first.
FORBIDDEN: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("a module path", re.compile(r"\b(?:impl|spec|runs|proofs|report|cfmpa)\.")),
    ("a dotted code name", re.compile(r"\w+\.\w+_\w+")),
    ("an obligation id", re.compile(r"\b[A-Z][A-Za-z]*\d*\.[a-z]")),
    ("a code identifier", re.compile(r"\b[a-z]+_[a-z_]+\b|\w+\(\)")),
    ("a ledger id", re.compile(r"\bA\d+\b")),
    ("a code constant", re.compile(r"\b[A-Z]{4,}\b")),
    ("a file name", re.compile(r"\w\.(?:py|toml|md|json)\b")),
)

_TERMINATES = ("BuiltDR ({variant}) always stops: each of its loops counts up to a bound fixed "
               "before it starts, and nothing inside a loop changes its counter or bound.")
_BUILTDR = ("BuiltDR as written in Algorithm 1 marks a cell of D_R blocked exactly when the "
            "subordinate arm at that cell meets the principal arm's swept region of that time "
            "step ({what}).")
_SEARCH = ("searchoptpath ({variant}) reports no path only when none exists, and otherwise "
           "returns a least-cost path that is collision-free at every step; the search inside it "
           "is taken at its contract unless its witness is checked.")
_IN_BOX = ("The principal arm's straight joint-space motion stays, within each time step, inside "
           "the box of angles that step's layer is built for, and inside the rest layer's box "
           "once it has stopped ({variant} variant).")
_COMPOSED = ("The safety theorem ({variant} variant): if D_R is as Theorems 1/3 say and the path is "
             "valid, the two arms share no point at any instant of the executed motion, in "
             "continuous time, not only at the grid's instants.")
_TRANSLATION = ("{workcell}, {variant}: the fast code's D_R and path meet Theorem {dr}'s and "
                "{search}'s postconditions at every cell; the search's answer is checked by its "
                "witness; the exact re-decision visits every cell of the path.")

#: Obligation id (or pattern) -> its plain summary.
SUMMARIES: dict[str, str] = {
    # Definitions 1-3, Lemmas 1-2
    "Def1.segment": "The segment between two points (Definition 1, read as t x + (1 - t) y) "
                    "contains both end points, is the same in either direction, and is a single "
                    "point when its ends coincide.",
    "Def1.segment_printed": "Definition 1 as printed, t x + (t - 1) y, leaves the segment's second "
                            "end point out: shown false with a counterexample (a typo for "
                            "(1 - t) y).",
    "Def2.is_convex": "A half-plane is convex, and so is the intersection of two convex sets "
                      "(Definition 2).",
    "Def3.convex_hull": "The convex hull of a set (Definition 3) contains the set, lies inside "
                        "every convex set containing it, and is itself convex.",
    "Lemma1.convex_monotone": "Lemma 1: a larger set has a larger convex hull.",
    "Lemma2.convex_union": "Lemma 2: the hulls of two sets together lie inside the hull of the "
                           "two sets' union.",
    # Separation and distance
    "Sep.separating_axis": "Two polygons whose corners lie strictly on opposite sides of a line "
                           "share no point.",
    "Sep.distance_monotone": "Declaring two regions apart when their distance exceeds a tiny "
                             "threshold is sound, and stays sound for any smaller regions inside "
                             "them.",
    # Swept regions
    "Margin.cos_bound": "1 - cos x is at most x^2/2 for every angle x: the calculus identities "
                        "are checked exactly, the mean value theorem step is taken on trust "
                        "(the ledger says so).",
    "Margin.arc_chord": "A point at distance r from a joint, turning through an angle g of at most "
                        "3.14 rad, stays within r g^2/8 of the straight line between its first "
                        "and last positions.",
    "Lemma.sweep_margin": "Anywhere inside a grid cell of joint angles, a link stays within a "
                          "margin of the hull of its positions at the cell's four corners; the "
                          "margin grows with the square of the cell's size.",
    "Margin.naive_hull": "The paper's hull of a link at its two end positions does not hold the "
                         "link in between: a link turning by 90 degrees leaves it, shown exactly.",
    # BuiltDR (Theorems 1, 3)
    "Thm1.builtdr": _BUILTDR.format(what="Theorem 1, the paper's original region"),
    "Thm1.termination": _TERMINATES.format(variant="original"),
    "Thm3.builtdr": _BUILTDR.format(what="Theorem 3, the paper's modified, one-sided region"),
    "Thm3.termination": _TERMINATES.format(variant="modified"),
    "Thm3.builtdr_tight": _BUILTDR.format(what="tight: swept between two instants only"),
    "Thm3.termination_tight": _TERMINATES.format(variant="tight"),
    "Thm3.box_nesting": "Per joint and time step, the tight variant's box of principal angles "
                        "lies inside the modified one, which lies inside the original one: each "
                        "variant sweeps no more than the one before.",
    # Paths (Properties 1-7, Definition 4)
    "Prop1.state_meaning": "Property 1: a cell marked 0 in D_R means the two arms share no point "
                           "there; a cell marked 1 means they do.",
    "Prop2.endpoints": "Property 2: a path starts at the subordinate arm's start cell and ends at "
                       "its goal cell.",
    "Prop3.layer_free": "Property 3: while the principal arm moves, every cell a path holds is "
                        "free in that time step's layer of D_R.",
    "Prop4.rest_free": "Property 4: once the principal arm has stopped, every cell a path holds "
                       "is free in the rest layer of D_R, however long it waits.",
    "Prop5.optpath_is_path": "Property 5: if any path exists, the least-cost path the planner "
                             "chooses is a path.",
    "Prop5.printed": "Property 5 as printed (the chosen path is always a path) is false when no "
                     "path exists, for example with the start cell blocked: the hypothesis that "
                     "one exists is missing.",
    "Prop6.opt_layer_free": "Property 6: the least-cost path holds only free cells while the "
                            "principal arm moves.",
    "Prop7.opt_rest_free": "Property 7: the least-cost path holds only cells free in the rest "
                           "layer once the principal arm has stopped.",
    "Def4.is_path_printed": "Definition 4 as printed lets a path end early and wait at a goal cell "
                            "that the principal arm sweeps later: shown false, so it does not keep "
                            "the subordinate safe.",
    "Def4.is_path_printed_off_grid": "Definition 4 as printed lets a path step through a cell "
                                     "outside the grid: shown false on a 3 x 3 grid with every "
                                     "cell blocked.",
    "Def4.is_path_fixed_safe": "With Definition 4 fixed, a path holds at every step a cell of the "
                               "grid that is free in the layer in force (the rest layer once the "
                               "principal arm has stopped).",
    # searchoptpath (Theorems 2, 4)
    "Thm2.searchoptpath": "Theorem 2: " + _SEARCH.format(variant="original"),
    "Thm4.searchoptpath": "Theorem 4: " + _SEARCH.format(variant="modified"),
    "Thm4.searchoptpath_tight": "Theorem 4, tight: " + _SEARCH.format(variant="tight"),
    # Witnesses
    "Witness.labels_sound": "When the cost labels the search hands over pass the witness "
                            "checker, no valid path costs less than the path returned: the path "
                            "is optimal.",
    "Witness.reachable_sound": "When the search reports no path and the set of reachable states "
                               "it hands over passes the witness checker, no valid path exists.",
    # Property 8
    "Prop8.printed": "Property 8 as printed (a smaller swept region keeps Theorem 1's D_R valid "
                     "for Theorem 3) is false: a cell blocked for the larger region may be free "
                     "for the smaller one.",
    "Prop8.intersection_monotone": "A smaller swept region can meet the other arm only where the "
                                   "larger one does.",
    "Prop8.subset_monotone": "Smaller swept regions in every layer block no more cells of D_R, "
                             "the rest layer included.",
    "Prop8.valid_transfer": "A path valid for the larger swept regions stays valid for the "
                            "smaller ones.",
    "Prop8.path_exists": "Whenever a path exists for the larger swept regions, one exists for the "
                         "smaller ones.",
    "Prop8.optimal_cost": "The least cost of a path for the smaller swept regions is at most the "
                          "least cost for the larger ones.",
    "Prop8.prestrength_thm4": "Theorem 4's safety follows from Theorem 2 stated for any regions, "
                              "by strengthening its precondition; the paper's route through "
                              "Property 8 is not valid.",
    # Trajectories
    "Certificate.lipschitz": (
        "The speed bound the motion certificate uses is safe as computed: no point of a link "
        "moves faster than it says, so the arms' distance changes no faster than the sum of two "
        "links' bounds, and the interval bound holds."),
    "Tolerance.tube_factor": (
        "The tolerance the tube reports is small enough: with the factor and the constant the "
        "code uses, twice the constant times the tolerance stays below the proved clearance, and "
        "no link point moves more than the constant times the tolerance."),
    "Exact.gap_formula": (
        "The gap the exact re-check computes along a separating direction, divided by that "
        "direction's length, never exceeds the true distance between the two regions, a "
        "tool's polygon included."),
    "Tolerance.tube": "A robot that tracks a plan proved clear by c to within delta in every "
                      "joint cannot collide while c > 2 L delta, L the largest reach of a link "
                      "about its two joints (metres per radian).",
    "Monitor.reference_speeds": "For a gap between two measured samples, the plan's speed the "
                                "monitor uses is at least its speed on every part of the plan "
                                "the gap overlaps, however many parts that is.",
    "Certificate.wiring": "For each time piece of a motion the certificate checks, the speed it "
                          "charges each arm is the speed that arm really has on that piece, and "
                          "the angles it samples are the motion's own.",
    "Certificate.pieces": "The certificate cuts the motion into pieces that each lie within one "
                          "path step, stop where the principal arm stops, and together cover "
                          "the whole motion without gaps.",
    "Monitor.between_samples": "Between two measured samples, a robot and a plan that each "
                               "move at most their speed limit stay within the larger sampled "
                               "deviation plus their speeds times half the gap.",
    # End-to-end safety
    "Safety.original.principal_in_layer_box": _IN_BOX.format(variant="original"),
    "Safety.modified.principal_in_layer_box": _IN_BOX.format(variant="modified"),
    "Safety.tight.principal_in_layer_box": _IN_BOX.format(variant="tight"),
    "Safety.subordinate_in_cell_box": "The subordinate arm, moving straight from cell to "
                                      "neighbouring cell each time step, stays inside the box of "
                                      "angles of the cell it holds, and rests at its goal once "
                                      "the path ends.",
    "Safety.region_soundness": "Every point of a link, at any joint angles inside a box, lies "
                               "inside the swept region the planner builds for that box: the "
                               "margin it adds covers the motion between the grid's sample "
                               "angles.",
    "Safety.region_statement": "Hence, by what a link and a swept region are (a rectangle of "
                               "the arm's geometry; the hull of the grown rectangles at the "
                               "sample angles), every point of either arm's links at angles in a "
                               "box is in that box's region.",
    "Safety.separation": "A pair of regions the planner frees, its rounded distance above "
                         "1e-9 m, is truly apart, since rounding errs by under 3e-11 m; links "
                         "in regions apart share no point.",
    "Safety.original.composition": _COMPOSED.format(variant="original"),
    "Safety.modified.composition": _COMPOSED.format(variant="modified"),
    "Safety.tight.composition": _COMPOSED.format(variant="tight"),
    "Safety.height_rule": ("Two parts whose height ranges the planner calls apart share no point "
                           "in space, whatever their outlines, so their planar test may be "
                           "skipped; ranges that only touch count as overlapping."),
    "Safety.tool_region": "Every point of a tool on the wrist, at any joint angles inside a box, "
                          "lies inside the swept region the planner builds for the tool: its "
                          "margin, taken from the farthest vertex, covers the motion between the "
                          "sample angles.",
    "Certificate.height_gap": "Between two parts at disjoint heights the motion check's distance, "
                              "made of the planar distance and the height gap, never exceeds "
                              "their true distance in space, and changes no faster than the "
                              "planar one.",
    # Per workcell
    "Scenario.*.time_grid": "{workcell}: the time steps cover the whole of the principal arm's "
                            "motion, for the numbers as written in the file and as the computer "
                            "stores them.",
    "Scenario.*.cspace_grid": "{workcell}: the subordinate arm's grid of joint angles is no "
                              "coarser than the angle its joints turn in one time step, as "
                              "written and as stored.",
    "Scenario.*.margin_side": "{workcell}: every angle step the swept regions use is at most "
                              "3.14 rad, and the margin the planner adds to each link is at least "
                              "the margin lemma's bound.",
    "Scenario.*.containment": "{workcell}: the tight swept region lies inside the modified one, "
                              "which lies inside the original one, in every layer and for both "
                              "links, decided exactly.",
    "Scenario.*.translation_original": _TRANSLATION.format(
        workcell="{workcell}", variant="original", dr="1", search="Theorem 2"),
    "Scenario.*.translation_modified": _TRANSLATION.format(
        workcell="{workcell}", variant="modified", dr="3", search="Theorem 4"),
    "Scenario.*.translation_tight": _TRANSLATION.format(
        workcell="{workcell}", variant="tight", dr="3", search="Theorem 4"),
}


def obligation_summary(ident: str, summaries: Mapping[str, str] | None = None) -> str | None:
    """The plain summary of obligation ``ident``, or None when it has none: an exact key first,
    then a pattern (``*`` one dot-free part, filled in as ``{workcell}``), then the longest key
    that is a dotted prefix of ``ident``."""
    table = SUMMARIES if summaries is None else summaries
    if ident in table:
        return table[ident]
    parts = ident.split(".")
    for key, text in table.items():
        kp = key.split(".")
        if "*" in kp and len(kp) == len(parts) and all(k in ("*", p) for k, p in zip(kp, parts)):
            filled = [p for k, p in zip(kp, parts) if k == "*"]
            return text.format(workcell=filled[0])
    prefixes = [k for k in table if "*" not in k and ident.startswith(k + ".")]
    return table[max(prefixes, key=len)] if prefixes else None


def summary_problems(idents: Iterable[str], summaries: Mapping[str, str] | None = None
                     ) -> list[str]:
    """What is wrong with the summaries of ``idents``: a missing one, one longer than
    MAX_CHARS, or one holding a FORBIDDEN name (each named, with the id)."""
    out = []
    for ident in idents:
        text = obligation_summary(ident, summaries)
        if text is None:
            out.append(f"{ident}: no summary")
            continue
        if len(text) > MAX_CHARS:
            out.append(f"{ident}: {len(text)} characters, more than {MAX_CHARS}")
        for what, pattern in FORBIDDEN:
            hit = pattern.search(text)
            if hit:
                out.append(f"{ident}: {what} {hit.group(0)!r} in {text!r}")
    return out
