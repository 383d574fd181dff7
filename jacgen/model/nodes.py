"""The plain nodes of the generated code, and the tolerances it compares with.

Selects, comparisons, `isfinite`, floor and ceiling are nodes of our own, decided only
between numbers, so that nothing asks sympy's assumption system about them while the
lowering (`lowering.py`) rebuilds expressions. Every algorithm builds with them and every
printer prints them. The tolerances are the symbols EPS, TINY and RANK, replaced by the
numbers of the build's real type when printed.
"""

import sympy
from sympy.core.logic import fuzzy_and
from sympy.logic.boolalg import BooleanAtom, BooleanFunction

EPS, TINY = sympy.symbols("EPS TINY", positive=True)
RANK = sympy.Symbol("RANK", positive=True)  # velocity_ik's singularity threshold (see `differential`)
# Their values by real type, replaced by the printers.
TOLERANCES = {"double": {EPS: sympy.Float(1e-12), TINY: sympy.Float(1e-24), RANK: sympy.Float(1e-12)},
              "float": {EPS: sympy.Float(1e-6), TINY: sympy.Float(1e-12), RANK: sympy.Float(1e-5)}}

TOLERANCE_SYMBOLS = frozenset(TOLERANCES["double"])


class IsFinite(BooleanFunction):
    """True when x is neither infinite nor NaN (`isfinite` in C; sympy's real symbols are
    finite by assumption, so this cannot be a comparison)."""

    nargs = 1


class Floor(sympy.Function):
    """floor(x), decided only for a number: sympy's own floor asks its assumption system
    whether x is an integer, real, ... each time CSE or a substitution rebuilds it (seconds
    per robot for the IK's angle wrapping)."""

    nargs = 1

    @classmethod
    def eval(cls, x):
        return sympy.floor(x) if x.is_Number else None


class Ceiling(sympy.Function):
    """ceil(x), decided only for a number (see Floor)."""

    nargs = 1

    @classmethod
    def eval(cls, x):
        return sympy.ceiling(x) if x.is_Number else None


class _Plain:
    """A comparison decided only between numbers and the positive tolerances (or of a value with
    itself), and -x against 0 turned into x against 0. sympy's own asks its assumption system
    about its sides each time it is built, and CSE and every substitution build each comparison
    again (a fifth of a robot's generation time). It sorts and prints as sympy's comparison of
    the same kind; its negation and its reversals (which sympy's And and Not form) are
    comparisons of this family."""

    def __new__(cls, lhs, rhs, evaluate=True):
        lhs, rhs = sympy.sympify(lhs), sympy.sympify(rhs)
        if evaluate:
            if lhs == rhs or (lhs.free_symbols | rhs.free_symbols) <= TOLERANCE_SYMBOLS:  # 1 >= -EPS: true
                decided = cls.kind(lhs, rhs)
                if isinstance(decided, BooleanAtom):
                    return decided
            if rhs == 0 and lhs.is_Mul and lhs.args[0] == -1:  # -x >= 0 is x <= 0: no negation to compute
                return PLAIN[REVERSED[cls.kind]](-lhs, rhs)
        return sympy.Basic.__new__(cls, lhs, rhs)

    @classmethod
    def class_key(cls):
        return 5, 0, cls.kind.__name__

    @property
    def negated(self):
        return PLAIN[NEGATED[self.kind]](*self.args)

    @property
    def reversed(self):
        return PLAIN[REVERSED[self.kind]](*self.args[::-1])

    @property
    def reversedsign(self):
        return PLAIN[REVERSED[self.kind]](-self.lhs, -self.rhs)


def _plain(name: str, kind: type) -> type:
    """The plain comparison of sympy's `kind`."""
    return type(name, (_Plain, kind), {"kind": kind, "__module__": __name__})


AtLeast, Above = _plain("AtLeast", sympy.GreaterThan), _plain("Above", sympy.StrictGreaterThan)
AtMost, Below = _plain("AtMost", sympy.LessThan), _plain("Below", sympy.StrictLessThan)
Equal, Unequal = _plain("Equal", sympy.Equality), _plain("Unequal", sympy.Unequality)
PLAIN = {cls.kind: cls for cls in (AtLeast, Above, AtMost, Below, Equal, Unequal)}
NEGATED = {sympy.Ge: sympy.Lt, sympy.Gt: sympy.Le, sympy.Le: sympy.Gt, sympy.Lt: sympy.Ge, sympy.Eq: sympy.Ne,
           sympy.Ne: sympy.Eq}
REVERSED = {sympy.Ge: sympy.Le, sympy.Gt: sympy.Lt, sympy.Le: sympy.Ge, sympy.Lt: sympy.Gt, sympy.Eq: sympy.Eq,
            sympy.Ne: sympy.Ne}


class Select(sympy.Function):
    """Args (condition, value, condition, value, ..., otherwise): the value of the first
    condition that holds, else `otherwise`; every value is computed. Decided only where a
    condition is a truth value or every value is the same (sympy's Piecewise asks its
    assumption system about each condition every time CSE or a substitution rebuilds it).
    A select in the otherwise position joins its parent, as Piecewise's pairs do."""

    is_commutative = True

    @classmethod
    def eval(cls, *args):
        *pairs, otherwise = args
        pairs = list(zip(pairs[::2], pairs[1::2]))
        changed = isinstance(otherwise, Select)
        if changed:
            pairs += otherwise.pairs
            otherwise = otherwise.args[-1]
        kept = []
        for condition, value in pairs:
            if condition is sympy.true:
                otherwise, changed = value, True
                break
            if condition is sympy.false:
                changed = True
            else:
                kept.append((condition, value))
        if all(value == otherwise for _, value in kept):
            return otherwise
        return cls(*(arg for pair in kept for arg in pair), otherwise) if changed else None

    @property
    def pairs(self) -> list[tuple[sympy.Basic, sympy.Expr]]:
        """(condition, value) in order; the last argument is the otherwise value."""
        return list(zip(self.args[:-1:2], self.args[1:-1:2]))

    def _eval_is_extended_real(self):
        return fuzzy_and(value.is_extended_real for value in self.args[1::2] + self.args[-1:])


def select(condition, if_true, if_false) -> sympy.Expr:
    """`if_true` where `condition` holds, else `if_false`; both are computed."""
    return Select(condition, if_true, if_false)
