"""The assumptions ledger: what `make prove` assumes rather than proves, and why that is fair."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["ASSUMPTIONS", "Assumption"]


@dataclass(frozen=True)
class Assumption:
    """One thing taken on trust: what it is, why it is reasonable, which obligations lean on it."""

    id: str
    what: str
    why: str
    used_by: str


ASSUMPTIONS: tuple[Assumption, ...] = (
    Assumption(
        "A1.rectangles",
        "Each link is the closed rectangle of width w around its joint-to-joint segment, "
        "extended by w/2 past both joints (docs/model.md §2); two arms collide iff such rectangles meet.",
        "The paper's convex polygon model; the width is the physical link's envelope, a datum "
        "the user supplies and is responsible for.",
        "all scenario checks; the meaning of Inter in Theorems 1-4"),
    Assumption(
        "A2.reals_for_floats",
        "The proofs reason over real numbers; the implementation computes in IEEE doubles, and "
        "declares a cell free only when the polygons' distance exceeds eps = 1e-9 m.",
        "Rounding errors of the polygon computations are of the order 1e-15 m at metre scale, "
        "six orders below eps. What this still covers: the cells a found path does not use. "
        "Every (layer, cell) a found path occupies is re-decided in arb ball arithmetic "
        "(plan.json's exact_gaps), and the containment of the variants' regions is decided "
        "exactly on the computed doubles, so neither rests on rounding.",
        "Sep.distance_monotone, Scenario.*.containment"),
    Assumption(
        "A3.trigonometry",
        "sin and cos enter Z3 as real unknowns with: c^2 + s^2 = 1; cos x >= 1 - x^2/2 for "
        "every real x; cos even and non-increasing on [0, pi]; sin >= 0 on [0, pi]; cos >= 0 on "
        "[0, pi/2]; rigid motions preserve distances and segments.",
        "Textbook facts; the second is reduced by Margin.cos_bound (sympy) to the mean value "
        "theorem, which is assumed.",
        "Margin.arc_chord, Margin.cos_bound, Lemma.sweep_margin"),
    Assumption(
        "A4.solvers",
        "Z3 (its unsat answers, without proof certificates) and sympy (simplify, solve) are "
        "sound; Python's Fraction arithmetic is exact.",
        "Widely used, heavily tested tools; every Z3 proof also passes a vacuity check, and "
        "negative tests show each encoding fails when a premise is removed. The SMT-LIB of "
        "every query is saved with its hash and is replayable in Z3 (the tests replay it); it "
        "uses Z3's extensions (lambda terms, arrays indexed by several sorts) and sets no logic, "
        "so another solver may reject it. sympy and data checks run under a wall-clock limit.",
        "every Z3 and sympy obligation"),
    Assumption(
        "A5.while_model",
        "The while-language programs (BuiltDR's loop nest; searchoptpath's top level) match "
        "cfmpa.impl's Python code.",
        "The programs are transcribed loop for loop from the code; the run-time contracts "
        "(docs/model.md §7) check the Python code against the same triples on real scenarios.",
        "Thm1.*, Thm3.*, Thm2.searchoptpath, Thm4.searchoptpath, Prop8.prestrength_thm4"),
    Assumption(
        "A6.search_contract",
        "The search that searchoptpath calls returns null iff no valid path exists, and "
        "otherwise a valid path of least (J1, J2) (Definition 5).",
        "Checked at run time in contract mode 'full' against an independent search (docs/model.md §7) "
        "and by the spec's own Dijkstra oracle in the tests.",
        "Thm2.searchoptpath, Thm4.searchoptpath, Prop8.prestrength_thm4"),
    Assumption(
        "A7.choice_and_wellfoundedness",
        "optpath is Hilbert's choice (as in the paper's HOL4 model), and (J1, J2) are natural "
        "numbers, so once a valid path exists a lexicographically least one exists.",
        "Lexicographic order on N x N is well-founded (standard); Z3 cannot do the induction, "
        "so the instance is a named hypothesis.",
        "Prop5.optpath_is_path, Prop6.opt_layer_free, Prop7.opt_rest_free"),
    Assumption(
        "A8.named_instances",
        "Where Z3 needs a universally quantified hypothesis used at a particular set, point or "
        "path (Definition 3's superset, Definition 2's points, Definition 5's rival path, a "
        "proved step lemma), the obligation names the instance.",
        "Instantiating a universal is sound: the statement says so where it happens, and Z3 "
        "checks everything else.",
        "Def3.convex_hull, Lemma1, Lemma2, Sep.*, Lemma.sweep_margin, Prop8.optimal_cost"),
    Assumption(
        "A9.regions_opaque",
        "In Theorems 1-4 the regions are opaque values and the intersection test uninterpreted; "
        "what Inter means (a common point) is used only in Property 1 and Property 8.",
        "The theorems then hold for any region construction; the construction's soundness is "
        "the margin lemma, and its monotonicity the per-scenario containment check.",
        "Thm1-Thm4, Prop1, Prop8.*"),
    Assumption(
        "A10.snap_slack",
        "impl.lattice_range snaps a box end onto a lattice point when it is within SNAP = 1e-9 "
        "of a spacing g (relative), so the sampled lattice may stop up to SNAP g (rad) short "
        "of the box; sweep_margin adds SNAP g R per joint (R the link's reach about that "
        "joint) to the margin.",
        "Turning a joint by an angle a moves any point at distance <= R from it by at most "
        "R a (chord <= arc), so a configuration in the uncovered sliver is within SNAP g R of "
        "one that the lemma's delta already covers; the triangle inequality adds the two. "
        "That sweep_margin adds at least this much is checked per scenario; the chord <= arc "
        "bound itself is assumed (as A3's facts).",
        "Scenario.*.margin_side, Lemma.sweep_margin, Scenario.*.containment"),
)
