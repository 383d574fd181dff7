"""Robots in parallel: `generate` and `verify` run each robot in a process of its own.

Robots share no symbolic work, so a process per robot divides the time by the processors
used. Workers are forked, or come from a fork server where forking is not safe (`_context`),
and get the Robot itself (it pickles in microseconds); what comes back must pickle too (text,
numbers). The longest robots start first, so that none starts last:
general 6R arms, then by number of joints (the structure is found in milliseconds).
"""

import multiprocessing
import os
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import TYPE_CHECKING, Callable, TypeVar

from jacgen import budget

if TYPE_CHECKING:  # the command line imports this module to start: sympy comes with the work
    from jacgen.inputs.robot import Robot

T = TypeVar("T")
THREADED_LIBRARIES = ("jax", "torch", "tensorflow")  # loaded, they make forking this process unsafe


def usable_cpus() -> int:
    """The processors this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def for_each_robot(work: Callable[..., T], robots: "list[Robot]", jobs: int, arguments: tuple = (),
                   done: "Callable[[Robot], None]" = lambda robot: None) -> list[T]:
    """[work(robot, *arguments) for robot in robots]: in this process when jobs is 1 (or there
    is one robot), else in up to `jobs` processes. `work` is a module-level function (it is
    sent by name). An exception in a worker is raised here, after cancelling what has not
    started. `done(robot)` as each one finishes."""
    if jobs <= 1 or len(robots) <= 1:
        results = []
        for robot in robots:
            results.append(work(robot, *arguments))
            done(robot)
        return results
    context = _context(work)
    results: dict[int, T] = {}
    with ProcessPoolExecutor(min(jobs, len(robots)), mp_context=context) as pool:
        order = sorted(range(len(robots)), key=lambda k: _expected_cost(robots[k]), reverse=True)
        futures = {pool.submit(_run, work, robots[k], arguments, budget.seconds()): k for k in order}
        try:
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                done(robots[futures[future]])
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)  # what has not started never will
            raise
    return [results[k] for k in range(len(robots))]


def _context(work: Callable) -> multiprocessing.context.BaseContext:
    """Forked workers where that is safe: they start with everything this process has
    imported and computed (the robots' structures in sympy's cache), 20% faster than from a
    fork server. Not safe once a library that runs its own threads is loaded (JAX, PyTorch,
    TensorFlow: a fork of a threaded process can deadlock; BLAS's threads handle fork
    themselves): then workers come from a fork server that has imported the module of
    `work` (and so jacgen and sympy) once, and where there is no fork server (Windows) they
    are spawned, each importing jacgen."""
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and not any(name in sys.modules for name in THREADED_LIBRARIES):
        return multiprocessing.get_context("fork")
    if "forkserver" not in methods:
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload([work.__module__])
    return context


def _run(work: Callable[..., T], robot: "Robot", arguments: tuple, seconds: float | None) -> T:
    """work in a worker, under the parent's budget."""
    budget.set_seconds(seconds)
    return work(robot, *arguments)


def _expected_cost(robot: "Robot") -> tuple[bool, int]:
    """What orders robots by generation time, roughly: the general 6R solver is the longest,
    then the more joints the longer."""
    from jacgen.solvers.model import Model

    return Model(robot).structure.solver == "general_6r", robot.dof
