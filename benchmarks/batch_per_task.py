"""Seconds per task of ``hybridsub batch`` on N tetrahedra (one level: the mesh work is about
nothing), one warmed local worker, two repeats, beside N bare Dask tasks on the same cluster.

usage: PYTHONPATH=CHECKOUT python benchmarks/batch_per_task.py [N]

It measures the hybridsub that ``PYTHONPATH`` (or the installed package) gives, so that two
checkouts can be compared in one sitting, alternately, under the same load:

    for i in 1 2; do
        PYTHONPATH=/path/to/old python benchmarks/batch_per_task.py 100
        PYTHONPATH=/path/to/new python benchmarks/batch_per_task.py 100
    done
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import time

import numpy as np

import hybridsub
from hybridsub._app.batch import local_cluster


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    d = tempfile.mkdtemp(prefix="hybridsub-per-task-")
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    F = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    try:
        for k in range(n):
            hybridsub.write_mesh(os.path.join(d, "in", f"t{k:05d}.obj"), V + 0.01 * k, F)
        cluster, client = local_cluster(1)
        with cluster, client:
            hybridsub.batch([os.path.join(d, "in", "t00000.obj")], os.path.join(d, "warm"), scheduler=client, levels=1)
            out = []
            for rep in range(2):
                s = hybridsub.batch(os.path.join(d, "in"), os.path.join(d, f"out{rep}"), scheduler=client, levels=1)
                t = time.perf_counter()
                client.gather(client.map(abs, range(n), pure=False))
                plain = time.perf_counter() - t
                out.append(f"{s.seconds / n * 1e3:.1f} ms/task (a bare Dask task {plain / n * 1e3:.1f} ms)")
        print(f"{hybridsub.__file__}: {'; '.join(out)}; load {os.getloadavg()[0]:.1f}")
    finally:
        shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
