"""A time budget: the safety net around each robot's exact singularity analysis.

The analysis is bounded by design (joint_ring.WORK_LIMIT and the size limits of singularities.py); the
budget is there only in case a limit is ever wrong, and no arm tried reaches it:

    singular = budget.within_budget(lambda: singularities.analyse(robot), lambda: singularities.unanalysed(robot),
                                    what=f"the singularity analysis of {robot.name}")

runs the work for at most `budget.seconds()` (set by `jacgen generate --budget`); when time
runs out it prints one warning on stderr and returns the fallback instead.

How: a real-time interval timer (`signal.setitimer`) whose SIGALRM handler raises
`BudgetExceeded` inside the work. sympy is pure Python, so the exception lands between two
bytecodes within milliseconds (a single long call into C, e.g. one huge integer product,
delays it until that call returns). Threads cannot be interrupted and a process would have
to pickle every expression back, so this is the cheapest sound choice. `BudgetExceeded`
derives from BaseException so that sympy's own `except Exception` blocks do not swallow
it, and the timer keeps firing every few milliseconds until the work has unwound (never
raising inside this module's own frames, so the step that catches it cannot be hit again,
nor inside a finalizer or a hook Python calls on the side, where it would only be printed).
Budgets nest: an inner step gets at most what its outer step has left. Signals only reach
the main thread, so elsewhere (or without `setitimer`) the work runs unbounded.

A fallback makes the output depend on the machine's speed: the warning says so, since
generated files are otherwise byte-identical everywhere.
"""

import gc
import signal
import sys
import threading
import time
from typing import Callable, TypeVar

T = TypeVar("T")

DEFAULT_SECONDS = 60.0
_REFIRE_SECONDS = 0.005  # after the deadline, until the work has unwound

_seconds: float | None = DEFAULT_SECONDS
_active: list["_Step"] = []  # the running steps, outermost first


class BudgetExceeded(BaseException):
    """Raised inside the work of the step whose time ran out; caught by that step."""

    def __init__(self, step: "_Step"):
        super().__init__(step.what)
        self.step = step


class _Step:
    def __init__(self, what: str, deadline: float):
        self.what, self.deadline, self.running = what, deadline, True


def set_seconds(seconds: float | None) -> None:
    """Set the budget of each step from now on; None or 0 means no limit."""
    global _seconds
    _seconds = seconds or None


def seconds() -> float | None:
    """The budget of each step in seconds (None: no limit)."""
    return _seconds


def within_budget(work: Callable[[], T], fallback: Callable[[], T], what: str,
                  seconds: float | None = None) -> T:
    """`work()` if it finishes within the budget, else `fallback()` and a warning on stderr.

    `seconds` overrides the module-wide budget for this call. `what` names the step in the
    warning ("factoring the singularity polynomial"). Exceptions of `work` propagate.
    """
    limit = _seconds if seconds is None else seconds
    if not limit or not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread():
        return work()
    now = time.monotonic()
    deadline = now + limit
    if _active:
        deadline = min(deadline, _active[-1].deadline)
    step = _Step(what, deadline)
    outermost = not _active
    previous_handler = signal.signal(signal.SIGALRM, _on_alarm) if outermost else None
    _active.append(step)
    try:
        _arm(now)
        return work()
    except BudgetExceeded as error:
        if error.step is not step:
            raise
        step.running = False
        _arm(time.monotonic())
        print(f"jacgen: warning: {what} took longer than {limit:g} s (--budget); using a cheaper exact "
              f"form, so this output depends on the machine's speed", file=sys.stderr)
        return fallback()
    finally:
        step.running = False
        _active.remove(step)
        if outermost:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous_handler)
        else:
            _arm(time.monotonic())


def _arm(now: float) -> None:
    """Set the timer for the earliest deadline of the running steps (off when none)."""
    running = [step.deadline for step in _active if step.running]
    if not running:
        signal.setitimer(signal.ITIMER_REAL, 0)
        return
    delay = max(min(running) - now, _REFIRE_SECONDS)
    signal.setitimer(signal.ITIMER_REAL, delay, _REFIRE_SECONDS)


def _on_alarm(signum, frame) -> None:
    """Interrupt the outermost running step whose deadline has passed.

    Never inside this module's own bookkeeping (the frame that caught an interruption and is
    about to disarm the timer): there the next tick, inside the work, will do.
    """
    if frame is not None and (frame.f_code in _BOOKKEEPING or _on_the_side(frame)):
        return
    now = time.monotonic()
    for step in _active:
        if step.running and step.deadline <= now:
            raise BudgetExceeded(step)


def _on_the_side(frame) -> bool:
    """Whether `frame` runs beside the work rather than in it: a finalizer, or a hook that Python
    calls on the side, a garbage collector's callback among them (an exception raised there is
    only printed, "Exception ignored in ...", and the work goes on). The next tick, 5 ms later,
    lands in the work instead."""
    collector = {getattr(callback, "__code__", None) for callback in gc.callbacks}
    while frame is not None and frame.f_code is not within_budget.__code__:
        if (frame.f_code.co_name == "__del__" or frame.f_code in collector
                or frame.f_globals.get("__name__", "").startswith(_SIDE_MODULES)):
            return True
        frame = frame.f_back
    return False


_SIDE_MODULES = ("traceback", "weakref", "_weakrefset", "warnings", "logging", "_pytest", "pluggy")
_BOOKKEEPING = (within_budget.__code__, _arm.__code__)
