"""ur5's fk + J and every IK branch for many poses on a dask.distributed cluster, through
ur5_native's gufuncs (README, section 6).

    .venv/bin/pip install -e '.[dask,native]'
    .venv/bin/python examples/dask_cluster.py --poses 10000000 [--scheduler tcp://host:8786]

Without --scheduler it starts a LocalCluster of this machine's processes, which import the
module `jacgen.arm` built (from its cache folder) by name: nothing to install on them. Workers
on other machines need the same cache folder ($JACGEN_CACHE_DIR on a shared disk), or
`jacgen generate --lang native` and `pip install` of the module there. Prints the mean number of
IK solutions per pose, the largest distance of a solution's pose from its target, and the
least manipulability met.
"""

import argparse
import sys
import time

try:
    import dask.array as da
    from dask.distributed import Client, LocalCluster
except ImportError:
    sys.exit("examples/dask_cluster.py needs dask: .venv/bin/pip install -e '.[dask,native]'")

import jacgen

FUNCTIONS = ("fk", "fk_jacobian", "ik_branches", "manipulability")


def survey(ur5, poses: int, chunk: int):
    """The statistics of `poses` random configurations, computed on the cluster in chunks."""
    q = da.random.uniform(-3.14, 3.14, size=(poses, ur5.DOF), chunks=(chunk, ur5.DOF))
    T, J = da.apply_gufunc(ur5.gufuncs.fk_jacobian, "(j)->(r,c),(k,j)", q,  # dask names the core dimensions
                           output_sizes={"r": 4, "c": 4, "k": 6}, output_dtypes=[float, float])
    q_ik, valid, in_limits = da.apply_gufunc(ur5.gufuncs.ik_branches, "(r,c)->(b,j),(b),(b)", T,
                                             output_sizes={"b": ur5.MAX_IK_SOLUTIONS, "j": ur5.DOF},
                                             output_dtypes=[float, bool, bool])
    reached = da.apply_gufunc(ur5.gufuncs.fk, "(j)->(r,c)", q_ik, output_sizes={"r": 4, "c": 4}, output_dtypes=float)
    error = da.where(valid[..., None, None], abs(reached - T[:, None]), 0).max()
    manipulability = da.apply_gufunc(ur5.gufuncs.manipulability, "(j)->()", q, output_dtypes=float)
    return da.compute(valid.sum(axis=1).mean(), error, manipulability.min())


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--poses", type=int, default=1_000_000)
    parser.add_argument("--chunk", type=int, default=1_000_000)
    parser.add_argument("--scheduler", default=None, help="the cluster's address (default: a LocalCluster here)")
    arguments = parser.parse_args()
    ur5 = jacgen.arm("ur5", backend="native", functions=FUNCTIONS)
    cluster = None if arguments.scheduler else LocalCluster(processes=True, threads_per_worker=1, dashboard_address=None)
    with Client(arguments.scheduler or cluster):
        start = time.perf_counter()
        solutions, worst, weakest = survey(ur5, arguments.poses, min(arguments.chunk, arguments.poses))
        seconds = time.perf_counter() - start
    print(f"{arguments.poses} poses in {seconds:.1f} s: {solutions:.3f} IK solutions per pose, "
          f"worst solution {worst:.1e} from its target, least manipulability {weakest:.2e}")
    if cluster is not None:
        cluster.close()


if __name__ == "__main__":
    main()
