#!/usr/bin/python3
"""Half the round trip of one message between two ranks, for message sizes from 8 B to 4 MB
(mpirun -n 2 pingpong.py OUT.json): the latency and bandwidth the scaling model of bench.py uses.
The fastest of several repeats per size (the machine is shared)."""
import json
import sys

import numpy as np
from mpi4py import MPI

comm = MPI.COMM_WORLD
rank = comm.Get_rank()
other = 1 - rank
out = {}
for size in [8, 64, 512, 4096, 32768, 262144, 1048576, 4194304]:
    buf = np.zeros(size // 8)
    reps = 200 if size <= 32768 else 40
    best = float("inf")
    for _ in range(5):
        comm.Barrier()
        t0 = MPI.Wtime()
        for _ in range(reps):
            if rank == 0:
                comm.Send(buf, dest=other, tag=1)
                comm.Recv(buf, source=other, tag=2)
            else:
                comm.Recv(buf, source=other, tag=1)
                comm.Send(buf, dest=other, tag=2)
        best = min(best, (MPI.Wtime() - t0) / reps / 2)
    out[size] = best
if rank == 0:
    json.dump(out, open(sys.argv[1], "w"), indent=1)
