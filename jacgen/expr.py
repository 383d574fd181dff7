"""The value grammar of robot files, parsed by hand (never eval or sympify of user text).

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom ("**" unary)?
    atom  := NUMBER | NAME | "(" expr ")" | "sqrt" "(" expr ")"

Every node is evaluated twice, exactly (sympy) and in floating point, so that the numpy
reference never depends on the symbolic path.
"""

import math
import re
import sys
from typing import Callable, NamedTuple

import sympy

MAX_LENGTH = 200
MAX_DEPTH = 32
MAX_MAGNITUDE = 1e6
MAX_EXPONENT = 16

_TOKEN = re.compile(
    r"\s*(?:(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<name>[A-Za-z_][A-Za-z0-9_]*)"
    r"|(?P<op>\*\*|[-+*/()]))"
)


class Value(NamedTuple):
    """A quantity of a robot file: its exact sympy form and its float value."""

    exact: sympy.Expr
    approx: float


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
    return _checked(sympy.Rational(text), float(text))


def _checked(exact: sympy.Expr, approx: float) -> Value:
    """The value, unless its float is out of range or has underflowed away from the exact one."""
    if not math.isfinite(approx) or abs(approx) > MAX_MAGNITUDE:
        raise ExpressionError(f"value {approx:g} is out of range (|value| <= {MAX_MAGNITUDE:g})")
    if abs(approx) < sys.float_info.min and exact.is_zero is False:
        raise ExpressionError(f"value {sympy.N(exact, 3)} is too small for a double (underflows)")
    return Value(exact, approx)


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
            value = _checked(value.exact + sign * right.exact, value.approx + sign * right.approx)
        return value

    def term(self, depth: int) -> Value:
        value = self.unary(depth)
        while self.peek() in ("*", "/"):
            if self.take()[1] == "*":
                right = self.unary(depth)
                value = _checked(value.exact * right.exact, value.approx * right.approx)
            else:
                right = self.unary(depth)
                if right.approx == 0:
                    raise ExpressionError("division by zero")
                value = _checked(value.exact / right.exact, value.approx / right.approx)
        return value

    def unary(self, depth: int) -> Value:
        if self.peek() in ("+", "-"):
            sign = 1 if self.take()[1] == "+" else -1
            value = self.unary(depth + 1)
            return Value(sign * value.exact, sign * value.approx)
        return self.power(depth)

    def power(self, depth: int) -> Value:
        base = self.atom(depth)
        if self.peek() != "**":
            return base
        self.take()
        exponent = self.unary(depth + 1)
        if abs(exponent.approx) > MAX_EXPONENT:
            raise ExpressionError(f"exponent {exponent.approx:g} too large (|exponent| <= {MAX_EXPONENT})")
        if base.approx < 0 and exponent.approx != int(exponent.approx):
            raise ExpressionError("negative number to a fractional power")
        if base.approx == 0 and exponent.approx < 0:
            raise ExpressionError("division by zero")
        return _checked(base.exact**exponent.exact, base.approx**exponent.approx)

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
                return Value(sympy.pi, math.pi)
            if text == "sqrt":
                self.take("(")
                argument = self.expr(depth + 1)
                self.take(")")
                if argument.approx < 0:
                    raise ExpressionError("sqrt of a negative number")
                return Value(sympy.sqrt(argument.exact), math.sqrt(argument.approx))
            return self.resolve(text)
        raise ExpressionError(f"unexpected {text!r}")
