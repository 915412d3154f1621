#!/usr/bin/python3
"""solid-rigid: a program for the solid role that moves free rigid bodies under the fluid's force
(rigid.py), written from common/PROTOCOL.md alone in Python with mpi4py. README.md has its scene
keys, numerics and limits.

    solid_rigid.py SCENE.toml [--out ROOT | --out-dir DIR] [--overwrite]"""
import json
import os
import signal
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

import mesh  # noqa: E402
import scene  # noqa: E402
import wire  # noqa: E402
from rigid import RigidBody  # noqa: E402

USAGE = "usage: solid-rigid SCENE.toml [--out ROOT | --out-dir DIR] [--overwrite]"


class Options:
    def __init__(self, argv):
        self.out_root, self.out_dir, self.overwrite, self.restart = "out", None, False, None
        self.lock = None
        positional = []
        args = iter(argv)
        for a in args:
            if a == "--overwrite":
                self.overwrite = True
            elif a in ("--out", "--out-dir", "--restart", "--time-limit"):
                v = next(args, None)
                if v is None:
                    raise wire.Failure(f"{a} needs a value; {USAGE}")
                if a == "--out":
                    self.out_root = v
                elif a == "--out-dir":
                    self.out_dir = v
                elif a == "--restart":
                    self.restart = v
            elif a.startswith("--"):
                raise wire.Failure(f"unknown option '{a}'; {USAGE}")
            else:
                positional.append(a)
        if len(positional) != 1:
            raise wire.Failure(f"expected one scene file, got {len(positional)}; {USAGE}")
        self.scene = positional[0]


class Program:
    """The solid side of the step sequence (PROTOCOL.md, "Every step n", "Coupled iterations",
    "End"), with the bodies' trajectories in OUT/solid_rigid.csv, one row per accepted step."""

    def __init__(self, link, folder, settings, bodies):
        self.link, self.folder = link, folder
        self.bodies = [RigidBody(b, settings["fluid_density"], settings["gravity"]) for b in bodies]
        self.csv = open(os.path.join(folder, "solid_rigid.csv"), "w")
        cols = ["time"]
        for b in self.bodies:
            cols += [f"{b.name}.{q}" for q in ("x", "y", "angle", "u", "v", "omega", "fx", "fy",
                                               "torque")]
        self.csv.write(",".join(cols) + "\n")
        self.steps = self.repeats = 0
        self.port_seconds = 0.0

    def meshes(self):
        w = wire.Writer("body_meshes")
        w.count(len(self.bodies))
        for b in self.bodies:
            # A free rigid body moves and takes the fluid's load: on the wire it is a body of
            # kind 0 ("elastic": nodes that move, nodal forces, velocities); a fixed one kind 1.
            w.string(b.name)
            w.i32(1 if b.fixed else 0)
            w.vec(b.x_ref.ravel(), np.float64)
            w.vec(b.tri.ravel(), np.int32)
            w.vec(mesh.surface_edges(b.tri).ravel(), np.int32)
            w.i32(1)  # rigid: no strain, so the fluid keeps its viscosity in it (version 8)
        w.i32(1)  # can_iterate
        return w.bytes()

    def state(self, time, step):
        w = wire.Writer("solid_state", step)
        w.f64(time)
        xs = [b.nodes() for b in self.bodies]
        w.count(len(xs))
        for x, _ in xs:
            w.vec(x, np.float64)
        w.count(len(xs))
        for _, v in xs:
            w.vec(v, np.float64)
        return w.bytes()

    def output(self, time):
        row = [time]
        for b in self.bodies:
            row += [b.C[0], b.C[1], b.th, b.V[0], b.V[1], b.W, b.F[0], b.F[1], b.T]
        self.csv.write(",".join(f"{v:.17g}" for v in row) + "\n")

    def run(self, effective):
        c = self.link
        c.send(self.meshes())
        c.send(self.state(0.0, 0))
        w = wire.Writer("effective_scene")
        w.string(effective)
        c.send(w.bytes())
        self.output(0.0)
        pending, saved, t_done = False, None, 0.0
        while True:
            r = c.recv("step_begin")
            n, t, dt, action = r.i64(), r.f64(), r.f64(), r.i32()
            iteration, may_repeat, checkpoint = r.i32(), r.i32(), r.i32()
            r.done()
            if pending and (action == 1 or iteration == 0):
                self.output(t_done)
                pending = False
            if action == 1:
                break
            expected = self.steps if iteration == 0 else self.steps - 1
            if n != expected or iteration < 0 or (iteration > 0 and saved is None):
                raise wire.Failure(f"protocol error: the coupler began step {n} iteration "
                                   f"{iteration} after step {self.steps - 1} was done")
            if checkpoint:
                sys.stderr.write(f"[solid] WARNING: solid-rigid cannot write checkpoints; the "
                                 f"state after step {n} is not saved\n")
            r = c.recv("solid_input")
            force, velocity = r.vec_list(np.float64), r.vec_list(np.float64)
            root_mass = r.vec_list(np.float64)
            r.done()
            t0 = wire.now()
            if len(force) != len(self.bodies) or (velocity and len(velocity) != len(self.bodies)):
                raise wire.Failure(f"protocol error: solid_input for {len(force)} bodies, the "
                                   f"solid has {len(self.bodies)}")
            if iteration == 0:
                saved = [b.save() for b in self.bodies]
            else:
                self.repeats += 1
                for b, s in zip(self.bodies, saved):
                    b.restore(s)
            for k, b in enumerate(self.bodies):
                f = force[k]
                if f.size and f.size != b.x_ref.size:
                    raise wire.Failure(f"protocol error: {f.size} force values for body "
                                       f"'{b.name}' of {b.x_ref.size // 2} nodes")
                m = root_mass[k] if k < len(root_mass) else None
                if m is not None and m.size and m.size != 3 * (b.x_ref.size // 2):
                    raise wire.Failure(f"protocol error: {m.size} root mass values for body "
                                       f"'{b.name}' of {b.x_ref.size // 2} nodes")
                b.advance(dt, f, velocity[k] if velocity else None, m)
            out = self.state(t + dt, n)
            self.port_seconds += wire.now() - t0
            c.send(out)
            self.steps, t_done = n + 1, t + dt
            pending = True
            if may_repeat == 0:
                self.output(t_done)
                pending = False
        self.csv.close()
        report = {"wall_time": MPI.Wtime() - T0, "steps": self.steps,
                  "port_seconds": self.port_seconds, "ahead_seconds": 0.0,
                  "bytes_sent": c.sent, "bytes_received": c.received, "program": "solid-rigid",
                  "bodies": {b.name: {"excess_mass": b.m, "excess_inertia": b.J, "area": b.area,
                                      "fixed": b.fixed} for b in self.bodies}}
        if self.repeats:
            report["repeated_steps"] = self.repeats
        w = wire.Writer("final_report")
        w.string(json.dumps(report))
        c.send(w.bytes())


def main():
    opts = Options(sys.argv[1:])
    raw, settings, _, table = scene.read(opts.scene)
    # The handshake first, so that every program of the job reaches it before any input error:
    # an error after it ends the job through MPI_Abort like any other.
    started = wire.start(opts, raw, settings["name"], settings["needs"])
    if started is None:
        return
    link, folder = started
    if opts.restart is not None:
        raise wire.Failure("solid-rigid cannot restart from a checkpoint (--restart)")
    if link is None:
        raise wire.Failure("solid-rigid runs in a coupled job only: the scene needs a [fluid] "
                           "(a scene with [solid] alone is run by the program solid)")
    if settings["checkpoint_interval"]:
        raise wire.Failure("solid-rigid cannot write checkpoints: remove output.checkpoint_interval "
                           f"(in {opts.scene})")
    bodies = scene.read_solid(table, settings, mesh.read_mesh)
    Program(link, folder, settings, bodies).run(scene.effective_toml(table))


T0 = MPI.Wtime()

if __name__ == "__main__":
    # A stop request (SIGUSR1 from ./fsi on Ctrl-C or SIGTERM) is the coupler's to act on: it ends
    # the run after the step under way. Python's default would kill this process.
    signal.signal(signal.SIGUSR1, signal.SIG_IGN)
    try:
        main()
    except wire.Failure as e:
        wire.abort(str(e))
    except Exception as e:  # noqa: BLE001 -- every error ends the whole job, never a hang
        wire.abort(f"{type(e).__name__}: {e}")
    if not MPI.Is_finalized():
        MPI.Finalize()
