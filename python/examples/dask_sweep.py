"""A cdpr-bench parameter study on a Dask cluster.

Each point of the grid is one task (`cdpr_bench.run_point`, which releases the GIL), scheduled by
Dask's distributed scheduler on whatever cluster the client connects to; the records are written
exactly as `cargo xtask sweep` writes them, so the two results.jsonl files are equal record for
record (wall times aside).

    python examples/dask_sweep.py GRID.toml OUT [SCHEDULER_ADDRESS]

Without a scheduler address it starts a LocalCluster of worker processes on this machine.
"""

import sys

import cdpr_bench
from dask.distributed import Client, LocalCluster


def sweep_on(client, grid_text):
    """Every point of the grid as a Dask task; the records in point order."""
    n = cdpr_bench.grid_points(grid_text)
    futures = client.map(
        cdpr_bench.run_point, [grid_text] * n, range(n), pure=False
    )
    return sorted(client.gather(futures), key=lambda r: r["point"])


def main(grid_path, out, address=None):
    with open(grid_path) as f:
        grid_text = f.read()
    if address is None:
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
            with Client(cluster) as client:
                records = sweep_on(client, grid_text)
    else:
        with Client(address) as client:
            records = sweep_on(client, grid_text)
    cdpr_bench.write_results(grid_text, records, out)
    failed = sum(r["status"] != "complete" for r in records)
    print(f"{len(records)} points, {failed} failed -> {out}/results.jsonl")


if __name__ == "__main__":
    main(*sys.argv[1:])
