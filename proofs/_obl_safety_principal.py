"""Part (a) of the end-to-end safety theorem (docs/model.md §10),
``Safety.<variant>.principal_in_layer_box``: theta_L(t) = start + (goal - start) min(t / Tf, 1)
lies in layer k's box (the variant's rule) for t in [k dt, (k+1) dt], and in the rest layer's box
for t >= N dt (N = max(1, ceil(Tf / dt))); Tf and N read from spec's code run on Z3 terms.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import z3

from ..spec import (
    Variant,
    ptp_angles,
    ptp_fraction,
)
from ..spec.z3defs import (
    Z3Dims,
)
from ._lemmas import Lemma, lemma
from ._z3vec import (
    Hyp,
    Vec,
)
from ._z3vec import vec as _v

_R = z3.RealSort()

# --- (a) the principal in its layer's box ------------------------------------------------------

def _mn(a: z3.ArithRef, b: z3.ArithRef) -> z3.ArithRef:
    return z3.If(a <= b, a, b)


def _mx(a: z3.ArithRef, b: z3.ArithRef) -> z3.ArithRef:
    return z3.If(a <= b, b, a)


@dataclass(frozen=True)
class Principal:
    """The principal's PTP motion (docs/model.md §2) over symbolic start, goal, omega, dt."""

    start: Vec
    goal: Vec
    omega: Vec
    dt: z3.ArithRef
    Tf: z3.ArithRef
    N: z3.ArithRef

    @classmethod
    def named(cls) -> Principal:
        return cls(_v("L.start"), _v("L.goal"), _v("L.omega"), z3.Real("dt"), z3.Real("Tf"),
                   Z3Dims.named().N)

    def theta(self, t: z3.ArithRef) -> Vec:
        """spec.ptp_angles (spec.left_angles' motion) run on the symbols."""
        return ptp_angles(self.start, self.goal, self.Tf, t)

    def tf_def(self) -> Hyp:
        tf, _ = counts_on_terms(self.start, self.goal, self.omega, self.dt)
        return ("Tf = max_q |goal_q - start_q| / omega_q (spec.exact_tf)", self.Tf == tf)

    def n_def(self) -> Hyp:
        tf, n = counts_on_terms(self.start, self.goal, self.omega, self.dt)
        # The code recomputes Tf inside exact_n: it is the named Tf (tf_def, a hypothesis).
        return ("N = max(1, ceil(Tf / dt)) (spec.exact_n)",
                self.N == z3.substitute(n, (tf, self.Tf)))

    def basics(self) -> tuple[Hyp, ...]:
        return (("dt > 0", self.dt > 0),
                ("omega_q > 0", z3.And(self.omega[0] > 0, self.omega[1] > 0)), self.tf_def())

    def box(self, variant: str, k: z3.ArithRef, *, sign_flip: bool = False) -> tuple[Vec, Vec]:
        """Layer k's box (k a real): spec.Variant.layer_box, the code's rule, run on the symbols
        (``sign_flip``, a test's mutant, points the modified box away from the goal)."""
        v = Variant(variant)
        if sign_flip:
            return v.layer_box(self.start, self.goal, self.omega, self.dt, self.Tf, k) if (
                v is not Variant.MODIFIED) else _flipped(self, k)
        return v.layer_box(self.start, self.goal, self.omega, self.dt, self.Tf, k)

    def rest_box(self, variant: str, **kw: bool) -> tuple[Vec, Vec]:
        """The rest layer's box: spec.Variant.rest_box (layer N-1's, or the goal for tight)."""
        v = Variant(variant)
        if kw.get("sign_flip") and v is Variant.MODIFIED:
            return _flipped(self, z3.ToReal(self.N) - 1)
        return v.rest_box(self.start, self.goal, self.omega, self.dt, self.Tf,
                          z3.ToReal(self.N))


def _exact(x: object, reading: str = "binary") -> object:
    """A reading of a number, on the proofs' symbols: the symbol is the reading's exact value."""
    return x


def counts_on_terms(start: Vec, goal: Vec, omega: Vec, dt: z3.ArithRef,
                    travel: Callable[..., object] | None = None
                    ) -> tuple[z3.ArithRef, z3.ArithRef]:
    """(Tf, N) as spec.exact_tf and spec.exact_n compute them (docs/model.md §2: the counts'
    one owner), their modules' own code run on the symbols (``module_on_terms``): a number's
    reading is the symbol itself, ``max`` an If, the exact ceiling ``spec.ceil_of`` (tested equal
    to the code's on fractions). ``travel`` replaces the travel time's function (the tests'
    mutant, from a planted copy of its module)."""
    from types import SimpleNamespace

    from ..spec import ceil_of, exact_tf
    from ._onterms import module_on_terms
    tt = travel or exact_tf.__globals__["travel_time"]
    counts = module_on_terms(tt, _read=_exact, ceil_fraction=ceil_of)
    grid = module_on_terms(exact_tf, travel_time=counts[tt.__name__],
                           time_steps=counts["time_steps"])
    s = SimpleNamespace(left=SimpleNamespace(start=start, goal=goal, omega=omega), dt=dt)
    return grid["exact_tf"](s), grid["exact_n"](s)


def _flipped(P: Principal, k: z3.ArithRef) -> tuple[Vec, Vec]:
    """The modified rule with s_q negated (the tests' mutant), through the same joint_box."""
    a = P.theta(k * P.dt)
    out = [Variant.MODIFIED.joint_box(a[q], a[q], P.omega[q] * P.dt,
                                      z3.Not(P.goal[q] > P.start[q])) for q in range(2)]
    return (out[0], out[1])


def in_box(theta: Vec, box: tuple[Vec, Vec]) -> z3.BoolRef:
    return z3.And(*[z3.And(box[q][0] <= theta[q], theta[q] <= box[q][1]) for q in range(2)])


def step_window(k: z3.ArithRef, t: z3.ArithRef, dt: z3.ArithRef) -> z3.BoolRef:
    K = z3.ToReal(k)
    return z3.And(K * dt <= t, t <= (K + 1) * dt)


def principal_steps(P: Principal) -> dict[str, Lemma]:
    """Small lemmas of (a), each decided by Z3 and by cvc5, that the motion and rest VCs use by
    substitution (cvc5 does not decide those VCs without them): the PTP fraction
    f(x) = spec.ptp_fraction(x, Tf) moves forward by at most dt / Tf over a window of dt
    (frac_step); the travel time bounds each joint's travel (travel); a joint's displacement
    over a forward step of the fraction is within omega_q dt, with the travel's sign (step_q);
    N dt covers Tf (n_covers), and from N dt on the fraction is 1 (at_rest)."""
    Tf, dt, om = P.Tf, P.dt, P.omega
    d = [P.goal[q] - P.start[q] for q in range(2)]
    a, b, x, t = z3.Reals("fs.a fs.b st.x ar.t")
    N = z3.ToReal(P.N)

    def f(y: z3.ArithRef) -> z3.ArithRef:
        return ptp_fraction(y, Tf)
    out: dict[str, Lemma] = {}
    key = "0 <= a <= b <= a + dt"
    out["frac_step"] = lemma(
        "frac_step", (("dt > 0", dt > 0), ("Tf >= 0", Tf >= 0),
                      (key, z3.And(0 <= a, a <= b, b <= a + dt))),
        z3.And(f(a) <= f(b), (f(b) - f(a)) * Tf <= dt, 0 <= f(a), f(b) <= 1), key,
        names=dict(a=a, b=b))
    travel = z3.And(Tf >= 0, *[z3.And(d[q] <= om[q] * Tf, -d[q] <= om[q] * Tf) for q in range(2)])
    tf = P.tf_def()
    out["travel"] = lemma("travel", (("omega_q > 0", z3.And(om[0] > 0, om[1] > 0)), tf), travel,
                          tf[0])
    for q in range(2):
        kq = "x Tf <= dt"
        out[f"step{q + 1}"] = lemma(
            f"step{q + 1}", (("omega_q > 0", om[q] > 0), ("dt > 0", dt > 0),
                             ("travel (Tf >= 0, |goal_q - start_q| <= omega_q Tf)",
                              z3.And(Tf >= 0, d[q] <= om[q] * Tf, -d[q] <= om[q] * Tf)),
                             ("x >= 0", x >= 0), (kq, x * Tf <= dt)),
            z3.And(d[q] * x <= om[q] * dt, -(d[q] * x) <= om[q] * dt,
                   z3.Implies(d[q] >= 0, d[q] * x >= 0), z3.Implies(d[q] <= 0, d[q] * x <= 0)),
            kq, names=dict(x=x))
    nd = P.n_def()
    out["n_covers"] = lemma("n_covers", (("dt > 0", dt > 0), ("Tf >= 0", Tf >= 0), nd),
                            z3.And(N * dt >= Tf, P.N >= 1), nd[0])
    kr = "t >= N dt"
    out["at_rest"] = lemma("at_rest", (("dt > 0", dt > 0), ("Tf >= 0", Tf >= 0),
                                       ("N dt >= Tf, N >= 1", z3.And(N * dt >= Tf, P.N >= 1)),
                                       (kr, t >= N * dt)),
                           z3.And(f(t) == 1, f(N * dt) == 1), kr, names=dict(t=t))
    return out


def _step_instances(steps: dict[str, Lemma], P: Principal, lo: z3.ArithRef, hi: z3.ArithRef,
                    at: str) -> list[Hyp]:
    """frac_step over [lo, hi] and step_q at the fraction's advance there."""
    adv = ptp_fraction(hi, P.Tf) - ptp_fraction(lo, P.Tf)
    out = steps["frac_step"].at(at, a=lo, b=hi)
    for q in (1, 2):
        out += steps[f"step{q}"].at(at, x=adv)
    return out


def principal_lemmas(variant: str, *, sign_flip: bool = False,
                     n_def: Hyp | None = None) -> tuple[Lemma, Lemma]:
    """(a) for ``variant``: the motion in layer k's box over [k dt, (k+1) dt], and in the rest
    layer's box from N dt on, each using principal_steps' lemmas by substitution.
    ``sign_flip`` and ``n_def`` are the tests' mutants."""
    P = Principal.named()
    steps = principal_steps(P)
    k, t = z3.Int("k"), z3.Real("t")
    K = z3.ToReal(k)
    key = "k dt <= t <= (k+1) dt"
    used = list(steps["travel"].at("the travel time"))
    for lo, hi, at in ((K * P.dt, t, "[k dt, t]"), (t, (K + 1) * P.dt, "[t, (k+1) dt]")):
        used += _step_instances(steps, P, lo, hi, at)
    used += steps["frac_step"].at("[k dt, (k+1) dt]", a=K * P.dt, b=(K + 1) * P.dt)
    motion = lemma("motion", P.basics() + (("k >= 0", k >= 0), (key, step_window(k, t, P.dt)))
                   + tuple(used),
                   in_box(P.theta(t), P.box(variant, K, sign_flip=sign_flip)), key,
                   names=dict(k=k, t=t))
    nd = n_def or P.n_def()
    N = z3.ToReal(P.N)
    used = list(steps["travel"].at("the travel time"))
    used += steps["n_covers"].at("N")
    used += steps["at_rest"].at("t", t=t)
    used += _step_instances(steps, P, (N - 1) * P.dt, N * P.dt, "[(N-1) dt, N dt]")
    rest = lemma("rest", P.basics() + (nd, ("t >= N dt", t >= N * P.dt)) + tuple(used),
                 in_box(P.theta(t), P.rest_box(variant, sign_flip=sign_flip)), nd[0],
                 names=dict(t=t))
    return motion, rest
