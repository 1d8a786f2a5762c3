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
        "Sep.distance_monotone, Scenario.*.containment, Safety.* (A11), Certificate.wiring, "
        "Monitor.reference_speeds"),
    Assumption(
        "A3.trigonometry",
        "sin and cos enter Z3 as real unknowns (in Safety.*, the uninterpreted functions Cos, "
        "Sin) with: c^2 + s^2 = 1; cos and sin of a sum and of a difference (cos(x + y) = cos x "
        "cos y - sin x sin y, sin(x + y) = sin x cos y + cos x sin y, and for x - y); cos x >= "
        "1 - x^2/2 for every real x; cos even and non-increasing on [0, pi]; sin >= 0 on [0, pi]; "
        "cos >= 0 on [0, pi/2] (each used at named points, with 3.14 < pi). That rigid motions "
        "preserve distances and chord points is not assumed: Safety.region_soundness proves it "
        "from the sum and difference rules, Lemma.sweep_margin from C^2 + S^2 = 1 (its "
        "rotation and frame VCs).",
        "Textbook facts; the second is reduced by Margin.cos_bound (sympy) to the mean value "
        "theorem, which is assumed.",
        "Margin.arc_chord, Margin.cos_bound, Lemma.sweep_margin, Safety.region_soundness"),
    Assumption(
        "A4.solvers",
        "Z3 (its unsat answers, without proof certificates) and sympy (simplify, solve) are "
        "sound; Python's Fraction arithmetic is exact.",
        "Widely used, heavily tested tools; every Z3 proof also passes a vacuity check, and "
        "negative tests show each encoding fails when a premise is removed. Every VC is also "
        "written in standard SMT-LIB 2.6 (a logic set, lambdas beta-reduced, arrays curried; "
        "the text whose hash proofs/obligations.lock pins) and replayed in cvc5: results.json "
        "says per VC which solvers confirm it (Z3, cvc5, or an exact sympy SOS certificate), "
        "and a cvc5 answer contradicting Z3's fails the run; the VCs only Z3 confirms are "
        "listed with cvc5's reason (mostly nonlinear arithmetic and quantified models). sympy "
        "and data checks run under a wall-clock limit.",
        "every Z3 and sympy obligation"),
    Assumption(
        "A5.while_model",
        "The while-language programs (BuiltDR's loop nest; searchoptpath's top level) are "
        "faithful models of cfmpa.impl's Python code. They are models, not transcriptions: "
        "impl.build_dr has one loop over the layers, vectorised over the cells (numpy), and "
        "impl.build_dr_fast is compiled; impl.search_opt_path has no loop at its top level (two "
        "early exits, then the search).",
        "BuiltDR's program is extracted from the syntax tree of its loop form "
        "(cfmpa.impl.builtdr_loop_nest, Algorithm 1 as written; proofs/_extract.py), with its "
        "invariants generated, so the assumption there is that Python runs that subset (counted "
        "range loops, if/else, stores) as the while-language means it; the loop form's agreement "
        "with build_dr and build_dr_fast is checked on data (bit for bit, in the tests), not "
        "proved; and cfmpa prove itself checks the D_R that build_dr_fast makes for every "
        "scenario it proves, every variant, against Theorem 1/3's postcondition at every cell "
        "(Scenario.*.translation_*), so for those workcells the bytes that run are checked, not "
        "modelled. searchoptpath's top level is written by hand: the two early exits (start "
        "blocked in layer 0, goal blocked in the rest layer) and the call, the search by its "
        "contract (A6); the model has no loop to match. The "
        "run-time contracts (docs/model.md §7) check the Python code against the same triples "
        "on real scenarios.",
        "Thm1.*, Thm3.*, Thm2.searchoptpath, Thm4.searchoptpath, Prop8.prestrength_thm4"),
    Assumption(
        "A6.search_contract",
        "The search that searchoptpath calls returns null iff no valid path exists, and "
        "otherwise a valid path of least (J1, J2) (Definition 5). Assumed only for runs that "
        "do not check it: in contract mode 'full', in `cfmpa check` and in cfmpa prove's "
        "Scenario.*.translation_* (the fast search on each proved workcell) the answer comes "
        "with a "
        "witness that spec.check_witness verifies (docs/model.md §11), and the run records "
        "that the checker ran and held (post.optimal); its acceptance implies the contract "
        "(Witness.labels_sound, Witness.reachable_sound), so there it is not assumed.",
        "The searches return their exact labels (or reachable sets) as witnesses; the tests "
        "check that these pass the checker and agree with the spec's opt_path on random D_R, "
        "and that corrupted witnesses are rejected. What such runs still trust is the "
        "checker's code (small, numpy, sharing nothing with impl/).",
        "Thm2.searchoptpath, Thm4.searchoptpath, Prop8.prestrength_thm4 (runs in sampled or "
        "off mode)"),
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
        "proved step lemma, a slice's maximum at the piece named, increasing times at the rows "
        "named), the obligation names the instance.",
        "Instantiating a universal is sound: the statement says so where it happens, and Z3 "
        "checks everything else.",
        "Def3.convex_hull, Lemma1, Lemma2, Sep.*, Lemma.sweep_margin, Prop8.optimal_cost, "
        "Certificate.wiring, Monitor.reference_speeds"),
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
        "bound itself is assumed (as A3's facts). Safety.region_soundness assumes neither: it "
        "derives the bound from A3's cos x >= 1 - x^2/2 and reads sweep_margin's own formula.",
        "Scenario.*.margin_side, Lemma.sweep_margin, Scenario.*.containment"),
    Assumption(
        "A11.safety_scope",
        "The end-to-end theorem (Safety.*) assumes only A2, A3, A4 and A12 (and, for a "
        "workcell with a tool or heights, A13): that the polygons and "
        "distances impl computes in doubles are the construction Safety.region_soundness "
        "proves sound, up to rounding (lattice indices by impl.lattice_range's formula, "
        "rectangles grown by impl.sweep_margin, their hull by impl.convex_hull (or, in "
        "build_dr_fast, its compiled twin, byte-equal in the tests), the "
        "subordinate's regions built at t_i = 0 and turned by t_i, reach by hypot, a cell free "
        "iff the distance exceeds eps); A12's bound on the float distance's error; A3's "
        "trigonometric facts; the solvers. It is a theorem "
        "about A1's model (the links are docs/model.md §2's rectangles). Its premises "
        "are not assumed but stated: D_R meets Theorem 1/3's postcondition (proved of "
        "BuiltDR's program, Thm1/Thm3.builtdr, under A5; checked on the cells at run time) and "
        "the path is valid under the fixed is_path (checked on every found path).",
        "Everything else in it is proved: the box rules contain the PTP motion and the "
        "subordinate's moves, the margin is derived from Margin.arc_chord (re-proved there) and "
        "compared with sweep_margin's formula, read from the code by running it on Z3 terms and "
        "checked against its floats on samples; the lattice model is checked against "
        "lattice_range on samples. Lemmas enter by substitution into proved VCs; "
        "Safety.region_statement derives, from Safety.region_soundness's lemmas, the statement "
        "the compositions use (a point of a link at a configuration of a box is a member of "
        "the region built for the box), with linkL, linkR and mem given their meaning by two "
        "definitions stated in it (a point of §2's rectangle at its local coordinates; the "
        "hull contains the convex combinations of the grown rectangles' points at the "
        "lattice configurations); norm chains are proved for every function standing for "
        "|v|^2, so for |v|^2.",
        "Safety.*"),
    Assumption(
        "A12.float_distance_error",
        "The distance BuiltDR compares with eps, computed in doubles (a box gap, a "
        "separating-axis gap along float edge normals, or the vertex-edge distance of "
        "impl._collide and spec.polygon_distance), differs from the exact value of the same "
        "lower bound of the distance, on the same doubles, by at most spec.DISTANCE_ERROR_M = "
        "64 u M (u = 2^-53, M = spec.MAX_COORD_M = 4000 m, the coordinate bound of every "
        "accepted scenario): about 2.8e-11 m.",
        "Each formula rounds at most about 15 times, each rounding off by u times a quantity of "
        "at most a few M; 64 u M leaves a factor of four. tests/spec/test_distance_error.py "
        "checks the bound against exact rational arithmetic on random convex polygons at "
        "coordinates up to M, near touching (where cancellation is worst). Safety.separation "
        "proves what it buys: with eps = spec.EPS above it, a freed pair is at a positive exact "
        "distance; an eps below it is refuted.",
        "Safety.separation, Safety.*.composition"),
    Assumption(
        "A13.tools_and_heights",
        "For a workcell with a tool or height intervals (docs/model.md §2), the end-to-end "
        "theorem covers every part: the compositions (Safety.<variant>.composition) range over "
        "every pair of parts the height rule keeps, the tool's region from Safety.tool_region's "
        "tool_statement, the pairs it drops by Safety.height_rule. Stated, not proved: (1) the "
        "polygon grown by the square is the hull of the vertices moved by the square's corners "
        "('hull of sums stated', Safety.tool_region); (2) a tool of fewer than 16 vertices is "
        "the 16-vertex one with a vertex repeated; (3) the numpy stand-in that runs impl's "
        "functions on terms (proofs/_onterms.py, _Numpy) computes what numpy computes; (4) "
        "the pairs BuiltDR tests, spec.pairs_to_test, are the pairs of spec.parts whose "
        "intervals (spec.part_height) spec.heights_overlap calls overlapping, as the "
        "compositions read them (an arm's tool present or not, each part's interval or None).",
        "Each stated step is tested or checked where it is used: the numpy stand-in against "
        "impl's floats on sample tools, the padding by the loader's MAX_TOOL_VERTICES, the grown "
        "polygon against impl.part_polygons, and pairs_to_test against heights_overlap on "
        "sample arms with and without tools and heights every time Safety.height_rule is built "
        "(a mismatch fails it). heights_overlap itself is read as the code is (run on terms), "
        "so a wrong comparison is refuted by a proof, not by this check.",
        "Safety.tool_region, Safety.height_rule, Safety.*.composition, the verdict rows of "
        "workcells with a tool or heights"),
)
