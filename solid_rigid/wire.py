"""The coupling protocol as common/PROTOCOL.md states it, from the solid's side: the start-up
handshake (the 48-byte announcement, the output folder, the intercommunicator) and the messages'
framing and layouts. Written from that page alone; nothing of the project's C++ is imported."""
import fcntl
import os
import socket
import struct
import sys
import time

import numpy as np
from mpi4py import MPI

VERSION = 9
ANNOUNCE_MAGIC = 0x31495346  # "FSI1"
MESSAGE_MAGIC = 0x4d495346   # "FSIM"
LINK_TAG_BASE = 7100         # MPI tag of MPI_Intercomm_create: this plus the solver's role number
ROLES = ("fluid", "solid", "fiber", "coupler")
SOLID = 1
COUPLER = 3
ANNOUNCE = struct.Struct("=IiiiiiQiiQ")  # magic, version, role, appnum, ranks, world rank,
                                             # scene hash, needed, pad, options hash: 48 bytes
assert ANNOUNCE.size == 48
HEADER = struct.Struct("=Iiiiq")               # magic, version, tag, 0, step: 24 bytes
LOCK_FILE = ".lock"

TAGS = {"grid_info": 1, "body_meshes": 2, "fiber_layout": 3, "effective_scene": 4,
        "step_begin": 10, "fluid_input": 11, "fluid_output": 12, "solid_input": 13,
        "solid_state": 14, "fiber_input": 15, "fiber_state": 16, "final_report": 20}
TAG_NAMES = {v: k for k, v in TAGS.items()}


class Failure(Exception):
    """An error of this program: `[solid] ERROR: <message>` and MPI_Abort (PROTOCOL.md, Errors)."""


def abort(message):
    sys.stderr.write(f"[solid] ERROR: {message}\n")
    sys.stderr.flush()
    MPI.COMM_WORLD.Abort(1)
    os._exit(1)


def fnv1a(data):
    """64-bit FNV-1a of bytes: the scene hash and the output options hash of the handshake."""
    h = 0xcbf29ce484222325
    for c in data:
        h ^= c
        h = (h * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return h


def options_text(opts):
    """The output options as one string, hashed in the announcement (PROTOCOL.md, Start-up)."""
    return "|".join([opts.out_root, opts.out_dir if opts.out_dir is not None else "-",
                     "true" if opts.overwrite else "false",
                     opts.restart if opts.restart is not None else "-", "-1"])


# ---- packing ----------------------------------------------------------------------------------

class Writer:
    def __init__(self, tag, step=0):
        self.parts = [HEADER.pack(MESSAGE_MAGIC, VERSION, TAGS[tag], 0, step)]

    def i32(self, x):
        self.parts.append(struct.pack("=i", x))

    def f64(self, x):
        self.parts.append(struct.pack("=d", x))

    def vec(self, a, dtype):
        a = np.ascontiguousarray(a, dtype=dtype)
        self.parts.append(struct.pack("=q", a.size))
        self.parts.append(a.tobytes())

    def string(self, s):
        b = s.encode()
        self.parts.append(struct.pack("=q", len(b)))
        self.parts.append(b)

    def count(self, n):
        self.parts.append(struct.pack("=q", n))

    def bytes(self):
        return b"".join(self.parts)


class Reader:
    def __init__(self, data, tag):
        self.data, self.pos = memoryview(data), 0
        magic, version, t, _, self.step = self._take(HEADER)
        if magic != MESSAGE_MAGIC:
            raise Failure(f"protocol error: bad message magic {magic:#x}")
        if version != VERSION:
            raise Failure(f"protocol error: message of version {version}, expected {VERSION}")
        if t != TAGS[tag]:
            raise Failure(f"protocol error: expected message '{tag}', got "
                          f"'{TAG_NAMES.get(t, t)}'")
        self.tag = tag

    def _take(self, st):
        if len(self.data) - self.pos < st.size:
            raise Failure(f"protocol error: message '{getattr(self, 'tag', '?')}' truncated")
        v = st.unpack_from(self.data, self.pos)
        self.pos += st.size
        return v

    def i32(self):
        return self._take(struct.Struct("=i"))[0]

    def i64(self):
        return self._take(struct.Struct("=q"))[0]

    def f64(self):
        return self._take(struct.Struct("=d"))[0]

    def vec(self, dtype):
        n = self.i64()
        size = np.dtype(dtype).itemsize
        if n < 0 or n * size > len(self.data) - self.pos:
            raise Failure(f"protocol error: vector length {n} does not fit message '{self.tag}'")
        a = np.frombuffer(self.data, dtype=dtype, count=n, offset=self.pos).copy()
        self.pos += n * size
        return a

    def vec_list(self, dtype):
        n = self.i64()
        if n < 0 or n > (1 << 24):
            raise Failure(f"protocol error: list length {n} out of range")
        return [self.vec(dtype) for _ in range(n)]

    def done(self):
        if self.pos != len(self.data):
            raise Failure(f"protocol error: message '{self.tag}' has trailing bytes")


# ---- the link to the coupler --------------------------------------------------------------------

class Link:
    """Rank 0 to rank 0 on the intercommunicator; waiting tests and yields the core."""

    def __init__(self, comm):
        self.comm = comm
        self.sent = 0
        self.received = 0

    def send(self, data):
        req = self.comm.Isend([data, MPI.BYTE], dest=0, tag=HEADER.unpack_from(data)[2])
        while not req.Test():
            os.sched_yield()
        self.sent += len(data)

    def recv(self, tag):
        status = MPI.Status()
        while True:
            msg = self.comm.Improbe(source=0, tag=MPI.ANY_TAG, status=status)
            if msg is not None:
                break
            os.sched_yield()
        if status.Get_tag() != TAGS[tag]:
            raise Failure(f"protocol error: expected message '{tag}' from coupler, got "
                          f"'{TAG_NAMES.get(status.Get_tag(), status.Get_tag())}'")
        buf = bytearray(status.Get_count(MPI.BYTE))
        msg.Recv([buf, MPI.BYTE])
        self.received += len(buf)
        return Reader(bytes(buf), tag)


# ---- start-up -------------------------------------------------------------------------------------

def _choose_out_dir(root, name, overwrite):
    os.makedirs(root, exist_ok=True)
    d = os.path.join(root, name)
    if overwrite:
        os.makedirs(d, exist_ok=True)
        return d
    k = 2
    while True:
        try:
            os.mkdir(d)
            return d
        except FileExistsError:
            d = os.path.join(root, f"{name}-{k}")
            k += 1


def _lock(d, scene):
    path = os.path.join(d, LOCK_FILE)
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        holder = open(path).readline().strip() or "holder unknown"
        raise Failure(f"output folder '{d}' is in use by another run that is still running "
                      f"({holder}); wait for it to end, or give this run another folder")
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"pid {os.getpid()} on {socket.gethostname()}, scene {scene}\n".encode(), 0)
    return fd  # kept open, and locked, until this process ends


def start(opts, scene_bytes, scene_name, needs):
    """The handshake of PROTOCOL.md "Programs and start-up", collective over MPI_COMM_WORLD.
    needs: (fluid, solid, fiber, coupler) booleans. Returns (Link or None, output folder), or
    None when the scene does not need a solid (after MPI_Finalize)."""
    world = MPI.COMM_WORLD
    rank, size = world.Get_rank(), world.Get_size()
    appnum = world.Get_attr(MPI.APPNUM)
    appnum = 0 if appnum is None else appnum
    local = world.Split(appnum, rank)
    me = ANNOUNCE.pack(ANNOUNCE_MAGIC, VERSION, SOLID, appnum, local.Get_size(), rank,
                       fnv1a(scene_bytes), 1 if needs[SOLID] else 0, 0,
                       fnv1a(options_text(opts).encode()))
    buf = bytearray(ANNOUNCE.size * size)
    world.Allgather([me, MPI.BYTE], [buf, MPI.BYTE])
    check_job([ANNOUNCE.unpack_from(buf, k * ANNOUNCE.size) for k in range(size)], needs,
              fnv1a(scene_bytes))

    job = world.Split(0 if needs[SOLID] else MPI.UNDEFINED, rank)
    if not needs[SOLID]:
        names = ", ".join(r for r, n in zip(ROLES, needs) if n)
        sys.stderr.write(f"[solid] not needed by scene '{scene_name}' (it needs {names}): "
                         "exiting\n")
        MPI.Finalize()
        return None
    folder = ""
    if job.Get_rank() == 0:
        d = opts.out_dir or _choose_out_dir(opts.out_root, scene_name, opts.overwrite)
        os.makedirs(d, exist_ok=True)
        opts.lock = _lock(d, opts.scene)
        others = [e for e in os.listdir(d) if e != LOCK_FILE]
        if opts.overwrite:
            import shutil
            for e in others:
                p = os.path.join(d, e)
                shutil.rmtree(p) if os.path.isdir(p) and not os.path.islink(p) else os.remove(p)
        elif opts.out_dir and others:
            raise Failure(f"output folder '{d}' exists and is not empty; pass --overwrite to "
                          "replace it")
        folder = d
    n = np.array([len(folder.encode())], dtype=np.int64)
    job.Bcast([n, MPI.LONG], root=0)
    text = bytearray(folder.encode()) if job.Get_rank() == 0 else bytearray(int(n[0]))
    job.Bcast([text, MPI.CHAR], root=0)
    folder = text.decode()
    if not needs[COUPLER]:
        return None, folder
    roles = np.zeros(job.Get_size(), dtype=np.int32)
    job.Allgather([np.array([SOLID], dtype=np.int32), MPI.INT], [roles, MPI.INT])
    coupler = int(np.flatnonzero(roles == COUPLER)[0])
    inter = local.Create_intercomm(0, job, coupler, LINK_TAG_BASE + SOLID)
    return Link(inter), folder


def check_job(all_, needs, my_hash):
    """The start-up checks; every process reaches the same verdict."""
    appnum = [-1] * len(ROLES)
    for magic, version, role, app, local_size, world_rank, scene_hash, _, _, options in all_:
        if magic != ANNOUNCE_MAGIC:
            raise Failure(f"process {world_rank} of the job is not a program of this project")
        if not 0 <= role < len(ROLES):
            raise Failure(f"process {world_rank} announced an unknown role")
        who = ROLES[role]
        if version != VERSION:
            raise Failure(f"protocol version mismatch: {who} speaks version {version}, solid "
                          f"speaks version {VERSION}; rebuild the programs from one source tree")
        if scene_hash != my_hash:
            raise Failure(f"scene mismatch: {who} read a scene file with different contents than "
                          "solid (same path on every process, same file?)")
        if options != all_[0][9]:
            raise Failure(f"{who} and {ROLES[all_[0][2]]} were given different output options "
                          "(--out, --out-dir, --overwrite, --restart); give every program of the "
                          "job the same arguments")
        if appnum[role] >= 0 and appnum[role] != app:
            raise Failure(f"role '{who}' was launched twice (programs {appnum[role]} and {app} "
                          "of the mpirun line); launch each program once")
        appnum[role] = app
        if local_size != 1:
            raise Failure(f"{who} was launched on {local_size} ranks; each program runs on 1 rank "
                          "(-n 1)")
    missing = [ROLES[r] for r in range(len(ROLES)) if needs[r] and appnum[r] < 0]
    if missing:
        launched = [ROLES[r] for r in range(len(ROLES)) if appnum[r] >= 0]
        raise Failure(f"the scene needs the program(s) {', '.join(missing)}, which were not "
                      f"launched (launched: {', '.join(launched)})")


def now():
    return time.perf_counter()
