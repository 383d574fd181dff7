"""The value grammar of robot files, parsed by hand (never eval or sympify of user text).

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom ("**" unary)?
    atom  := NUMBER | NAME | "(" expr ")" | "sqrt" "(" expr ")"

Every node is evaluated twice, exactly and in floating point, so that the numpy reference
never depends on the symbolic path. The exact form is kept as a recipe of the operations
and built in sympy when first read (`Value.exact`): loading and validating a robot file
does not import sympy.
"""

import math
import re
import sys
from typing import Callable

MAX_LENGTH = 200
MAX_DEPTH = 32
MAX_MAGNITUDE = 1e6
MAX_EXPONENT = 16
MAX_DIGITS = 64  # of a number's mantissa, before any exact arithmetic on it

# ASCII only: no other script's digits ("١٢" is not 12) or spaces.
_NUMBER = r"(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_TOKEN = re.compile(
    rf"[ \t\r\n]*(?:(?P<number>{_NUMBER})|(?P<name>[A-Za-z_][A-Za-z0-9_]*)|(?P<op>\*\*|[-+*/()]))", re.ASCII)
_DECIMAL = re.compile(rf"[+-]?{_NUMBER}", re.ASCII)
_PARTS = re.compile(r"([+-]?)([0-9]*)\.?([0-9]*)(?:[eE]([+-]?[0-9]+))?", re.ASCII)


class Value:
    """A quantity of a robot file: its exact sympy form and its float value.

    `Value(exact, approx)` takes a sympy expression, or a recipe that `exact` builds when
    first read: ("integer", n), ("decimal", m, e) for m 10^e, ("pi",), ("symbol", name) (a
    parameter kept symbolic), or (operation, form, ...) on other Values' forms, for "add",
    "mul", "div", "pow", "neg" and "sqrt" (`combined`)."""

    __slots__ = ("_exact", "approx")

    def __init__(self, exact, approx: float):
        self._exact, self.approx = exact, approx

    @property
    def exact(self):
        if isinstance(self._exact, tuple):
            from sympy.core.parameters import distribute, evaluate

            with evaluate(True), distribute(True):  # the same form whatever sympy's state where it is first read
                self._exact = _built(self._exact)
        return self._exact

    @property
    def symbolic(self) -> bool:
        """Whether it holds a parameter kept symbolic."""
        return _symbolic(self._exact)

    def __eq__(self, other) -> bool:
        return isinstance(other, Value) and self.approx == other.approx and self.exact == other.exact

    def __hash__(self) -> int:
        return hash((self.exact, self.approx))

    def __repr__(self) -> str:
        return f"Value({self.exact!r}, {self.approx!r})"


def combined(operation: str, approx: float, *values: Value) -> Value:
    """The Value of `operation` on `values`, as a recipe of their forms, whose float is `approx`."""
    return Value((operation, *(value._exact for value in values)), approx)


def _built(form):
    """The sympy expression of a form (see Value)."""
    if not isinstance(form, tuple):
        return form
    import sympy

    operation, *arguments = form
    if operation == "integer":
        return sympy.Integer(arguments[0])
    if operation == "decimal":
        return sympy.Integer(arguments[0]) * sympy.Integer(10) ** arguments[1]
    if operation == "pi":
        return sympy.pi
    if operation == "symbol":
        return sympy.Symbol(arguments[0], real=True)
    a, *rest = map(_built, arguments)
    if operation == "neg":
        return -1 * a  # as a product, which distributes over a sum (sympy's -a does not)
    if operation == "sqrt":
        return sympy.sqrt(a)
    b = rest[0]
    return a + b if operation == "add" else a * b if operation == "mul" else a / b if operation == "div" else a**b


def _symbolic(form) -> bool:
    if isinstance(form, tuple):
        return form[0] == "symbol" or any(_symbolic(x) for x in form[1:])
    return bool(getattr(form, "free_symbols", False))


class ExpressionError(ValueError):
    """The text is not a valid value; the message says why."""


def tokenize(text: str) -> list[tuple[str, str]]:
    tokens, position = [], 0
    text = text.rstrip()
    while position < len(text):
        match = _TOKEN.match(text, position)
        if not match or match.end() == position:
            raise ExpressionError(f"unexpected character {text[position:].lstrip()[:1]!r}")
        kind = match.lastgroup
        tokens.append((kind, match.group(kind)))
        position = match.end()
    return tokens


def parse(text: str, resolve: Callable[[str], Value]) -> Value:
    """Parse `text`; `resolve(name)` gives the Value of a parameter name."""
    if len(text) > MAX_LENGTH:
        raise ExpressionError(f"expression longer than {MAX_LENGTH} characters")
    tokens = tokenize(text)
    if not tokens:
        raise ExpressionError("empty expression")
    parser = _Parser(tokens, resolve)
    value = parser.expr(0)
    if parser.position != len(tokens):
        raise ExpressionError(f"unexpected {tokens[parser.position][1]!r}")
    return value


def number(text: str) -> Value:
    """A decimal number ([+-]digits[.digits][e[+-]digits], ASCII), exact. Its size is checked
    from its digits before any exact arithmetic, so 1e999999999 or 5,000 digits cost nothing."""
    if not _DECIMAL.fullmatch(text):
        raise ExpressionError(f"not a decimal number: {text[:40]!r}")
    sign, integer, fraction, exponent = _PARTS.fullmatch(text).groups()
    if len(integer) + len(fraction) > MAX_DIGITS:
        raise ExpressionError(f"number with more than {MAX_DIGITS} digits")
    significant = (integer + fraction).lstrip("0")
    if not significant:
        return Value(("integer", 0), 0.0)
    if exponent and len(exponent.lstrip("+-").lstrip("0")) > 4:  # beyond any double: out of range or underflow
        exponent = "-99999" if exponent.startswith("-") else "99999"
    scale = int(exponent or 0) - len(fraction)  # the value is int(integer + fraction) * 10**scale
    order = len(significant) + scale  # 10**(order - 1) <= |value| < 10**order
    if order > 7:
        raise ExpressionError(f"value {text[:40]} is out of range (|value| <= {MAX_MAGNITUDE:g})")
    if order < -330:
        raise ExpressionError(f"value {text[:40]} is too small for a double (underflows)")
    magnitude = ("decimal", int(integer + fraction), scale)
    return _checked(Value(("neg", magnitude) if sign == "-" else magnitude, float(text)))


def _checked(value: Value) -> Value:
    """The value, unless its float is out of range or has underflowed away from the exact one
    (only then is its exact form built)."""
    if not math.isfinite(value.approx) or abs(value.approx) > MAX_MAGNITUDE:
        raise ExpressionError(f"value {value.approx:g} is out of range (|value| <= {MAX_MAGNITUDE:g})")
    if abs(value.approx) < sys.float_info.min and value.exact.is_zero is False:
        raise ExpressionError(f"value {value.exact.evalf(3)} is too small for a double (underflows)")
    return value


class _Parser:
    def __init__(self, tokens, resolve):
        self.tokens, self.resolve, self.position = tokens, resolve, 0

    def peek(self) -> str | None:
        return self.tokens[self.position][1] if self.position < len(self.tokens) else None

    def take(self, expected: str | None = None) -> tuple[str, str]:
        if self.position >= len(self.tokens):
            raise ExpressionError("expression ends too early")
        token = self.tokens[self.position]
        if expected is not None and token[1] != expected:
            raise ExpressionError(f"expected {expected!r}, got {token[1]!r}")
        self.position += 1
        return token

    def expr(self, depth: int) -> Value:
        if depth > MAX_DEPTH:
            raise ExpressionError("expression nested too deeply")
        value = self.term(depth)
        while self.peek() in ("+", "-"):
            sign = 1 if self.take()[1] == "+" else -1
            right = self.term(depth)
            right = right if sign > 0 else combined("neg", -right.approx, right)
            value = _checked(combined("add", value.approx + right.approx, value, right))
        return value

    def term(self, depth: int) -> Value:
        value = self.unary(depth)
        while self.peek() in ("*", "/"):
            if self.take()[1] == "*":
                right = self.unary(depth)
                value = _checked(combined("mul", value.approx * right.approx, value, right))
            else:
                right = self.unary(depth)
                if right.approx == 0:
                    raise ExpressionError("division by zero")
                value = _checked(combined("div", value.approx / right.approx, value, right))
        return value

    def unary(self, depth: int) -> Value:
        if self.peek() in ("+", "-"):
            sign = 1 if self.take()[1] == "+" else -1
            value = self.unary(depth + 1)
            return value if sign > 0 else combined("neg", -value.approx, value)
        return self.power(depth)

    def power(self, depth: int) -> Value:
        base = self.atom(depth)
        if self.peek() != "**":
            return base
        self.take()
        exponent = self.unary(depth + 1)
        if exponent.symbolic:  # its domain (a negative base, 0**x) would depend on the runtime value
            raise ExpressionError("an exponent may not hold a symbolic parameter")
        if abs(exponent.approx) > MAX_EXPONENT:
            raise ExpressionError(f"exponent {exponent.approx:g} too large (|exponent| <= {MAX_EXPONENT})")
        if base.approx < 0 and exponent.approx != int(exponent.approx):
            raise ExpressionError("negative number to a fractional power")
        if base.approx == 0 and exponent.approx < 0:
            raise ExpressionError("division by zero")
        return _checked(combined("pow", base.approx**exponent.approx, base, exponent))

    def atom(self, depth: int) -> Value:
        kind, text = self.take()
        if kind == "number":
            return number(text)
        if text == "(":
            value = self.expr(depth + 1)
            self.take(")")
            return value
        if kind == "name":
            if text == "pi":
                return Value(("pi",), math.pi)
            if text == "sqrt":
                self.take("(")
                argument = self.expr(depth + 1)
                self.take(")")
                if argument.approx < 0:
                    raise ExpressionError("sqrt of a negative number")
                return combined("sqrt", math.sqrt(argument.approx), argument)
            return self.resolve(text)
        raise ExpressionError(f"unexpected {text!r}")
