"""Z3's SMT-LIB text of sub-lists of a list of formulas, from one print of the whole list.

Every Z3 check of ``cfmpa prove`` runs in a context rebuilt from Z3's own text of its formulas
(``text_of``), and several checks read nearly the same formulas: a VC's vacuity
and proof checks share its hypotheses, and the premise controls each drop one hypothesis of a
composition (docs/model.md §10.3). Printing is the costly part (about a microsecond a
character), so ``Printed`` prints the whole list once and gives, for any sub-list that keeps the
order, the text Z3 prints for it, byte for byte: Z3's search, its resource count (which
``_limits`` calibrates) and so every verdict depend on that text.

How Z3 prints a list (checked on every bundled obligation by tests/proofs/test_z3text.py): the
declarations (the uninterpreted sorts first, then the functions and constants), one line each,
then one ``(assert ...)`` per formula, in order. Each assertion's text depends on that formula
alone (its ``let`` names restart at ``a!1``). The declarations come in the order Z3's collector
first meets the symbols, formula after formula: a formula adds, in its own order, the symbols no
earlier formula has. So a kept formula's new symbols in a sub-list are in the whole list's
order when it met all of them first in the whole list too; when a dropped formula met some of
them first, their order is the one the kept formula shows printed alone (once, then cached).
Whatever this module cannot split with certainty (a command other than declare-sort,
declare-fun and assert, two declarations of one name, a declaration no formula uses, an order
that does not follow the formulas, a formula printed alone unlike in the list) it prints
whole: the derived text is Z3's or not given at all.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

import numpy as np
import z3

__all__ = ["Printed", "commands", "text_of"]

#: The structure of Z3's text: |quoted symbols|, "strings" ("" is a quote inside one),
#: comments, parentheses. Only these can hide or hold parentheses.
_STRUCTURE = re.compile(r'\|[^|]*\||"(?:[^"]|"")*"|;[^\n]*|[()]')
#: Tokens of one command: a quoted symbol, a string, a parenthesis, or a plain atom.
_TOKEN = re.compile(r'\|[^|]*\||"(?:[^"]|"")*"|;[^\n]*|[()]|[^\s()|";]+')
#: An assertion with a quantifier or a lambda (whose bound names may shadow a declared one).
_QUANTIFIES = re.compile(r"\((?:forall|exists|lambda) ")
#: The names Z3 gives its let bindings, and the first name each let binds.
_ALIAS = re.compile(r"a!\d+")
_FIRST_LET = re.compile(r"\(let \(\(([^\s()]+) ")
_DECLARES = ("declare-sort", "declare-fun")


def text_of(formulas: Sequence[z3.BoolRef]) -> str:
    """Z3's SMT-LIB text of ``formulas`` (declarations, then one assert each, in order): what
    every check of ``cfmpa prove`` is rebuilt from (``_obligation._solver``)."""
    s = z3.Solver()
    for f in formulas:
        s.add(f)
    return str(s.sexpr())


def commands(text: str) -> list[str] | None:
    """The top-level commands of Z3's text, each as printed (its newlines inside kept), or None
    if the text is not commands each starting a line and separated by one newline."""
    if text.isascii() and not any(c in text for c in '|";'):
        return _plain_commands(text)
    out: list[str] = []
    depth = 0
    start = 0
    for m in _STRUCTURE.finditer(text):
        tok = m.group()
        if tok == "(":
            if depth == 0:
                # Between two commands Z3 writes exactly one newline.
                if text[start:m.start()] != ("" if not out else "\n"):
                    return None
                start = m.start()
            depth += 1
        elif tok == ")":
            depth -= 1
            if depth < 0:
                return None
            if depth == 0:
                out.append(text[start:m.end()])
                start = m.end()
        elif depth == 0:
            return None                 # a string, symbol or comment outside any command
    if depth != 0 or text[start:] != ("\n" if out else ""):
        return None
    return out


def _plain_commands(text: str) -> list[str] | None:
    """``commands`` of a text with no quoted symbol, string or comment: every parenthesis is
    structure, so the depth after each character is a running sum (vectorised: texts run to
    hundreds of kilobytes)."""
    b = np.frombuffer(text.encode("ascii"), dtype=np.uint8)
    step = (b == ord("(")).astype(np.int32) - (b == ord(")")).astype(np.int32)
    depth = np.cumsum(step)
    if len(depth) and (depth.min() < 0 or depth[-1] != 0):
        return None
    ends = np.flatnonzero((depth == 0) & (step == -1))
    # An opening parenthesis that reaches depth 1 was read at depth 0: a command starts there.
    starts = np.flatnonzero((depth == 1) & (step == 1))
    if len(starts) != len(ends):
        return None
    out = [text[a:e + 1] for a, e in zip(starts.tolist(), ends.tolist())]
    gaps = [text[e + 1:a] for e, a in zip(ends.tolist(), starts.tolist()[1:])]
    lead = text[:starts[0]] if len(starts) else text
    tail = text[ends[-1] + 1:] if len(ends) else ""
    if lead != "" or tail != ("\n" if out else "") or any(g != "\n" for g in gaps):
        return None
    return out


def _tree(cmd: str) -> list[object]:
    """The command as nested lists of tokens (iteratively: formulas can be deep)."""
    root: list[object] = []
    stack = [root]
    for tok in _TOKEN.findall(cmd):
        if tok == "(":
            node: list[object] = []
            stack[-1].append(node)
            stack.append(node)
        elif tok == ")":
            stack.pop()
        elif not tok.startswith(";"):
            stack[-1].append(tok)
    return root


def _free_uses(cmd: str, names: set[str]) -> set[str]:
    """The names of ``names`` that ``cmd`` uses free: not as a bound variable of a quantifier,
    lambda or let in whose scope it stands, nor as an attribute's symbol (``:qid``)."""
    if not _QUANTIFIES.search(cmd):
        free = set(_TOKEN.findall(cmd)) & names
        # Z3 names its let bindings a!1, a!2, ... (ALIAS_PREFIX in its ast_smt2_pp.cpp): a let
        # can shadow a declared name only if that name has this shape.
        if not any(_ALIAS.fullmatch(n) for n in free) and all(
                _ALIAS.fullmatch(n) for n in _FIRST_LET.findall(cmd)):
            return free
    used: set[str] = set()
    stack: list[tuple[object, frozenset[str]]] = [(_tree(cmd), frozenset())]
    while stack:
        node, bound = stack.pop()
        if isinstance(node, str):
            if node in names and node not in bound:
                used.add(node)
            continue
        assert isinstance(node, list)
        head = node[0] if node else None
        if head in ("forall", "exists", "lambda") and len(node) >= 3 and isinstance(node[1], list):
            inner = set(bound)
            for pair in node[1]:
                if isinstance(pair, list) and pair and isinstance(pair[0], str):
                    inner.add(pair[0])
                    stack += [(s, bound) for s in pair[1:]]     # the sorts
            stack += [(b, frozenset(inner)) for b in node[2:]]
        elif head == "let" and len(node) >= 3 and isinstance(node[1], list):
            inner = set(bound)
            for pair in node[1]:            # parallel: each value in the outer scope
                if isinstance(pair, list) and pair and isinstance(pair[0], str):
                    inner.add(pair[0])
                    stack += [(v, bound) for v in pair[1:]]
            stack += [(b, frozenset(inner)) for b in node[2:]]
        elif head == "!":
            items = node[1:]
            k = 0
            while k < len(items):
                item = items[k]
                if isinstance(item, str) and item.startswith(":") and item not in (
                        ":pattern", ":no-pattern"):
                    k += 2                  # :qid name, :skolemid name, :weight n
                    continue
                stack.append((item, bound))
                k += 1
        else:
            stack += [(c, bound) for c in node]
    return used


class Printed:
    """Z3's text of ``formulas``, printed once, and of any sub-list of them in their order.

    ``text(keep)`` equals ``text_of([formulas[k] for k in keep])`` byte for byte.
    ``reprints`` counts the prints it needed beyond the first: of one formula alone (once each)
    when a dropped formula met first a symbol a kept one uses, of the whole sub-list when the
    text is not one this module can split with certainty.
    """

    def __init__(self, formulas: Sequence[z3.BoolRef]) -> None:
        self.formulas = list(formulas)
        self.full = text_of(self.formulas)
        self.reprints = 0
        self._asserts: list[str] = []
        self._uses: list[frozenset[str]] = []       # per formula, the declared names it needs
        self._first: dict[str, int] = {}            # the first formula that needs each
        self._pos: dict[str, int] = {}              # its place among the declarations
        self._decl: dict[str, tuple[str, str]] = {}  # its declaration: (kind, command)
        self._own: dict[int, list[str] | None] = {}
        self._exact = self._analyse()

    def _analyse(self) -> bool:
        cmds = commands(self.full)
        if cmds is None:
            return False
        decls: list[tuple[str, str, str]] = []          # (kind, name, command)
        asserts: list[str] = []
        for c in cmds:
            head = c[1:c.find(" ")] if " " in c else ""
            if head == "assert":
                asserts.append(c)
            elif head in _DECLARES and not asserts:
                decls.append((head, _TOKEN.findall(c)[2], c))
            else:
                return False                # a definition, or a declaration after an assert
        names = [n for _, n, _ in decls]
        if len(asserts) != len(self.formulas) or len(set(names)) != len(names):
            return False
        kinds = [k for k, _, _ in decls]
        if kinds != sorted(kinds, key=_DECLARES.index):
            return False                    # sorts not all before the functions
        sorts = {n for k, n, _ in decls if k == "declare-sort"}
        # A function's declaration needs the sorts of its signature.
        needs = {n: set(_TOKEN.findall(c)[3:]) & sorts for k, n, c in decls
                 if k == "declare-fun"}
        every = set(names)
        uses: list[frozenset[str]] = []
        for a in asserts:
            u = _free_uses(a, every)
            for n in list(u):
                u |= needs.get(n, set())
            uses.append(frozenset(u))
        first: dict[str, int] = {}
        for k, needed in enumerate(uses):
            for n in needed:
                first.setdefault(n, k)
        if set(first) != every:
            return False                    # a declaration no formula uses: not Z3's rule
        for kind in _DECLARES:
            order = [first[n] for k, n, _ in decls if k == kind]
            if order != sorted(order):
                return False                # not in the order the formulas meet them
        self._asserts = asserts
        self._uses = uses
        self._first = first
        self._pos = {n: i for i, n in enumerate(names)}
        self._decl = {n: (k, c) for k, n, c in decls}
        return True

    def text(self, keep: Iterable[int]) -> str:
        """Z3's text of the formulas at ``keep`` (increasing indices), in that order."""
        idx = list(keep)
        if any(not 0 <= k < len(self.formulas) for k in idx):
            raise IndexError(f"keep {idx} is not within the {len(self.formulas)} formulas")
        if any(a >= b for a, b in zip(idx, idx[1:])):
            raise ValueError(f"keep {idx} does not increase")
        if idx == list(range(len(self.formulas))):
            return self.full
        if not idx:
            return text_of([])
        if not self._exact:
            return self._reprint(idx)
        order: list[str] = []
        seen: set[str] = set()
        for k in idx:
            new = [n for n in self._uses[k] if n not in seen]
            if len(new) < 2 or all(self._first[n] == k for n in new):
                # All met first by this formula in the whole list too: the whole list's order
                # (or a single one, which has no order to get wrong).
                new.sort(key=self._pos.__getitem__)
            else:
                # Some met first by a dropped formula: the order this formula meets them in,
                # from a print of it alone.
                own = self._own_order(k)
                if own is None:
                    return self._reprint(idx)
                new = [n for n in own if n not in seen]
            seen.update(new)
            order += new
        lines = [self._decl[n][1] for kind in _DECLARES for n in order
                 if self._decl[n][0] == kind]
        return "".join(line + "\n" for line in lines + [self._asserts[k] for k in idx])

    def _own_order(self, k: int) -> list[str] | None:
        """The order in which Z3 declares the symbols of formula ``k`` printed alone (once a
        process per formula), or None if that print is not what the whole list's says of it."""
        if k not in self._own:
            self.reprints += 1
            cmds = commands(text_of([self.formulas[k]]))
            own: list[str] | None = None
            if cmds is not None and cmds[-1] == self._asserts[k]:
                decls = [_TOKEN.findall(c) for c in cmds[:-1]]
                names = [t[2] for t in decls]
                if (all(t[1] in _DECLARES for t in decls)
                        and len(set(names)) == len(names) and set(names) == self._uses[k]):
                    own = names
            self._own[k] = own
        return self._own[k]

    def _reprint(self, idx: list[int]) -> str:
        self.reprints += 1
        return text_of([self.formulas[k] for k in idx])
