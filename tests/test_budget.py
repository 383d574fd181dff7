"""The time budget of symbolic steps: runaway sympy work is interrupted on time, the cheaper
fallback is used with one warning, and everything else behaves as if there were no budget."""

import gc
import random
import signal
import sys
import threading
import time

import pytest
import sympy
from click.testing import CliRunner

from jacgen import budget
from jacgen.cli import main


@pytest.fixture(autouse=True)
def restore_budget():
    saved = budget.seconds()
    yield
    budget.set_seconds(saved)


def hard_polynomial() -> sympy.Expr:
    """A product of three random sparse polynomials in 5 variables: `factor` takes minutes."""
    x = sympy.symbols("x0:5")
    rng = random.Random(1)

    def poly(degree, terms):
        return sum(rng.randint(-9, 9) * sympy.prod(v ** rng.randint(0, degree) for v in x) for _ in range(terms))

    return sympy.expand(poly(8, 16) * poly(8, 16) * poly(3, 5))


def spin(seconds: float) -> str:
    """Pure-Python busy work for `seconds` (interruptible between bytecodes)."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        pass
    return "finished"


def test_runaway_factor_falls_back_within_budget(capsys):
    polynomial = hard_polynomial()
    start = time.monotonic()
    result = budget.within_budget(lambda: sympy.factor(polynomial), lambda: polynomial,
                                  what="factoring a test polynomial", seconds=1.0)
    elapsed = time.monotonic() - start
    assert result is polynomial
    assert elapsed < 2.0, elapsed
    warning = capsys.readouterr().err
    assert warning.startswith("jacgen: warning: factoring a test polynomial took longer than 1 s (--budget)")
    assert warning.count("\n") == 1
    # sympy is still sound after the interruption
    x, y = sympy.symbols("x y")
    assert sympy.factor(x**2 - y**2) == (x - y) * (x + y)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_quick_work_returns_its_result_silently(capsys):
    x = sympy.Symbol("x")
    assert budget.within_budget(lambda: sympy.factor(x**2 - 1), lambda: None, what="quick", seconds=5) == (x - 1) * (x + 1)
    assert capsys.readouterr().err == ""
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_handler_and_timer_are_restored():
    previous = signal.getsignal(signal.SIGALRM)
    budget.within_budget(lambda: spin(0.3), lambda: "fallback", what="spin", seconds=0.05)
    budget.within_budget(lambda: 1, lambda: 2, what="quick", seconds=1)
    assert signal.getsignal(signal.SIGALRM) is previous
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_errors_of_the_work_propagate():
    def fail():
        raise ValueError("bad input")

    with pytest.raises(ValueError, match="bad input"):
        budget.within_budget(fail, lambda: None, what="failing", seconds=1)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_inner_step_gets_at_most_what_the_outer_has_left(capsys):
    start = time.monotonic()
    result = budget.within_budget(
        lambda: budget.within_budget(lambda: spin(5), lambda: "inner fallback", what="inner", seconds=10),
        lambda: "outer fallback", what="outer", seconds=0.3)
    assert result == "outer fallback"
    assert time.monotonic() - start < 1.0
    assert "outer took longer" in capsys.readouterr().err


def test_inner_timeout_leaves_the_outer_step_running(capsys):
    def outer():
        inner = budget.within_budget(lambda: spin(5), lambda: "inner fallback", what="inner", seconds=0.1)
        return inner, spin(0.2)

    assert budget.within_budget(outer, lambda: "outer fallback", what="outer", seconds=5) == ("inner fallback", "finished")
    err = capsys.readouterr().err
    assert err.count("jacgen: warning:") == 1 and "inner took longer" in err


def test_no_limit_and_other_threads_run_unbounded(capsys):
    budget.set_seconds(0)
    assert budget.seconds() is None
    assert budget.within_budget(lambda: spin(0.1), lambda: "fallback", what="spin") == "finished"
    results = []
    thread = threading.Thread(target=lambda: results.append(
        budget.within_budget(lambda: spin(0.2), lambda: "fallback", what="spin", seconds=0.05)))
    thread.start()
    thread.join()
    assert results == ["finished"]
    assert capsys.readouterr().err == ""


def test_generate_sets_the_budget(tmp_path):
    robot = tmp_path / "planar.yaml"
    robot.write_text("name: planar\nconvention: standard\njoints:\n"
                     "  - {type: revolute, a: 1, alpha: 0, d: 0}\n  - {type: revolute, a: 1, alpha: 0, d: 0}\n"
                     "task: [x, y]\n")
    result = CliRunner().invoke(main, ["generate", str(robot), "-o", str(tmp_path / "out"), "--lang", "python",
                                       "--budget", "7.5"])
    assert result.exit_code == 0, result.output
    assert budget.seconds() == 7.5


def test_analysis_out_of_budget_falls_back_to_the_numeric_condition(capsys):
    """The budget is a safety net on the robot's whole exact analysis: past it, the numeric
    Gram determinant alone is the condition, with a warning."""
    from jacgen.emission.generator import Generator
    from conftest import robot

    budget.set_seconds(0.01)
    try:
        singular = Generator(robot("panda")).singularities
    finally:
        budget.set_seconds(budget.DEFAULT_SECONDS)
    assert not singular.complete and not singular.factors and "--budget" in singular.note
    assert "the singularity analysis of panda took longer than 0.01 s" in capsys.readouterr().err



def test_an_alarm_in_a_garbage_collector_callback_waits_for_the_work(monkeypatch):
    """A gc callback runs inside whatever allocation triggered the collection; an interruption
    raised there would only be printed ("Exception ignored in ...") and lost. The alarm waits
    for the next tick, in the work, which falls back."""
    ignored = []
    monkeypatch.setattr(sys, "unraisablehook", ignored.append)

    def slow_callback(phase, info):
        if phase == "start":
            spin(0.02)

    def work():
        end = time.monotonic() + 5
        while time.monotonic() < end:
            cycle = []
            cycle.append(cycle)  # garbage that only the collector frees
        return "finished"

    gc.callbacks.append(slow_callback)
    try:
        result = budget.within_budget(work, lambda: "fallback", what="a gc test", seconds=0.3)
    finally:
        gc.callbacks.remove(slow_callback)
    assert result == "fallback"
    assert ignored == []
