#!/usr/bin/python3
"""Check what a running coupled job exchanged against values computed here, independently.

  check_exchange.py RUN_DIR --check NAME [--check NAME]... [--tol T] [--from-step N]
                    [--field U0x,U0y,Gxx,Gxy,Gyx,Gyy]

RUN_DIR holds coupler_exchange.h5 (written by the coupler with [coupler.diagnostics]
dump_every > 0) and scene.effective.toml. Checks (each over every dumped step from --from-step):

  areas         Σ α|V| over the u-faces, and over the v-faces, equals the bodies' area (from the
                node positions the solid sent), relative to that area.
  fractions     α of every face equals |V ∩ bodies| / |V| from clipping the triangles here (with
                their periodic images); no face the bodies touch is missing.
  solid-velocity  ū_s of every face equals the exact mean over V ∩ bodies: for a rigid body with
                [solid.body.motion] the analytic rigid velocity at the centroid of V ∩ T; for an
                elastic body the FE field (linear on each triangle) at that centroid; relative to
                the largest node speed.
  solid-forces  Σ_a F_a + Σ_V f_s |V| = 0 relative to Σ_V |f_s| |V| (which must be > 0).
  fluid-field   the fluid's samples u^n (the faces U(X^n) is interpolated from) equal the linear
                field u = U0 + G x (--field) at their faces: the fluid holds it (else the next
                check tests nothing); relative to the largest |u| of the field on the markers.
  fiber-velocity  U(X^n) at every marker equals the field there; same scale.
  fiber-forces  Σ f_f h_x h_y (on the fluid) = −Σ_m F_m w_m (on the fibers; w = ds, ds/2 at the
                ends), relative to Σ |F| w (which must be > 0).
  root-loads    the nodal forces that carry each fiber's root load to its body have the load's
                resultant and, about the root point, its moment; relative to |F| + |M|/L. The
                root masses lumped on the nodes sum to the fibers' and have their first moment
                about the root points (sum x_a m_a = sum p m); relative to |m| (|m| L).

Prints each check's worst relative error; exits 1 when one exceeds --tol (default 1e-12) or a
check had nothing to check.
"""
import argparse
import math
import os
import sys
import tomllib

import h5py
import numpy as np


# ---- geometry (written for this script: clipping, areas, centroids) -------------------------
def clip_box(poly, x0, x1, y0, y1):
    """The polygon `poly` (list of (x, y)) clipped to the box, by the four half-planes in turn."""
    def clip(pts, inside, cut):
        out = []
        for k in range(len(pts)):
            p, q = pts[k - 1], pts[k]
            ip, iq = inside(p), inside(q)
            if iq:
                if not ip:
                    out.append(cut(p, q))
                out.append(q)
            elif ip:
                out.append(cut(p, q))
        return out

    def at_x(c):
        return lambda p, q: (c, p[1] + (q[1] - p[1]) * (c - p[0]) / (q[0] - p[0]))

    def at_y(c):
        return lambda p, q: (p[0] + (q[0] - p[0]) * (c - p[1]) / (q[1] - p[1]), c)

    pts = poly
    for inside, cut in ((lambda p: p[0] >= x0, at_x(x0)), (lambda p: p[0] <= x1, at_x(x1)),
                        (lambda p: p[1] >= y0, at_y(y0)), (lambda p: p[1] <= y1, at_y(y1))):
        if not pts:
            return []
        pts = clip(pts, inside, cut)
    return pts


def area_centroid(pts):
    """Signed area and centroid of a simple polygon (shoelace), in coordinates relative to its
    first vertex: a thin sliver far from the origin keeps its digits."""
    ox, oy = pts[0]
    a = cx = cy = 0.0
    n = len(pts)
    for k in range(n):
        (x0, y0), (x1, y1) = pts[k], pts[(k + 1) % n]
        x0, y0, x1, y1 = x0 - ox, y0 - oy, x1 - ox, y1 - oy
        c = x0 * y1 - x1 * y0
        a += c
        cx += (x0 + x1) * c
        cy += (y0 + y1) * c
    if a == 0:
        return 0.0, (ox, oy)
    return 0.5 * a, (ox + cx / (3 * a), oy + cy / (3 * a))


def barycentric(t, q):
    (ax, ay), (bx, by), (cx, cy) = t
    d = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay)
    l1 = ((q[0] - ax) * (cy - ay) - (cx - ax) * (q[1] - ay)) / d
    l2 = ((bx - ax) * (q[1] - ay) - (q[0] - ax) * (by - ay)) / d
    return 1 - l1 - l2, l1, l2


# ---- the grid's face families ---------------------------------------------------------------
class Family:
    """u- or v-faces: control-volume box edges ex, ey, flat index i + ni j, face positions."""

    def __init__(self, xf, yf, px, py, name):
        def centres(f, periodic, n):
            nc = len(f) - 1
            def c(k):
                if k < 0:
                    return 0.5 * (f[nc - 1] + f[nc]) - (f[nc] - f[0]) if periodic else f[0] - 0.5 * (f[1] - f[0])
                if k >= nc:
                    return f[nc] + 0.5 * (f[nc] - f[nc - 1])
                return 0.5 * (f[k] + f[k + 1])
            return np.array([c(k - 1) for k in range(n + 1)])
        nx, ny = len(xf) - 1, len(yf) - 1
        if name == "u":
            self.ni = nx if px else nx + 1
            self.nj = ny
            self.ex, self.ey = centres(xf, px, self.ni), np.asarray(yf)
            self.x = np.asarray(xf[:self.ni])
            self.y = 0.5 * (np.asarray(yf[:-1]) + np.asarray(yf[1:]))
        else:
            self.ni = nx
            self.nj = ny if py else ny + 1
            self.ex, self.ey = np.asarray(xf), centres(yf, py, self.nj)
            self.x = 0.5 * (np.asarray(xf[:-1]) + np.asarray(xf[1:]))
            self.y = np.asarray(yf[:self.nj])

    def volume(self, idx):
        i, j = idx % self.ni, idx // self.ni
        return (self.ex[i + 1] - self.ex[i]) * (self.ey[j + 1] - self.ey[j])

    def position(self, idx):
        return self.x[idx % self.ni], self.y[idx // self.ni]


class Run:
    def __init__(self, run_dir):
        self.h5 = h5py.File(os.path.join(run_dir, "coupler_exchange.h5"), "r")
        with open(os.path.join(run_dir, "scene.effective.toml"), "rb") as f:
            self.scene = tomllib.load(f)
        g = self.h5["grid"]
        self.xf, self.yf = g["x_face"][()], g["y_face"][()]
        self.px, self.py = bool(g.attrs["periodic_x"]), bool(g.attrs["periodic_y"])
        self.lx, self.ly = self.xf[-1] - self.xf[0], self.yf[-1] - self.yf[0]
        self.fam = {c: Family(self.xf, self.yf, self.px, self.py, c) for c in "uv"}
        self.bodies = [k[5:] for k in self.h5 if k.startswith("body_")]
        self.fibers = [k[6:] for k in self.h5 if k.startswith("fiber_")]
        self.steps = sorted(k for k in self.h5 if k.startswith("step_"))

    def get(self, step, name, dtype=float):
        s = self.h5[step]
        return s[name][()].astype(dtype) if name in s else np.zeros(0, dtype)

    def motion(self, body):
        for b in self.scene.get("solid", {}).get("body", []):
            if b["name"] == body and b.get("kind") == "rigid" and "motion" in b:
                return b["motion"]
        return None

    def images(self, tri_xy):
        """The triangle and its periodic images that can meet the domain."""
        sx = [-self.lx, 0.0, self.lx] if self.px else [0.0]
        sy = [-self.ly, 0.0, self.ly] if self.py else [0.0]
        return [[(x + a, y + b) for x, y in tri_xy] for a in sx for b in sy]


def exact_faces(run, step):
    """Per family: {face: [Σ|V∩T|, Σ |V∩T| ū_exact]} by clipping every triangle here."""
    t = run.h5[step].attrs["time"]
    out = {"u": {}, "v": {}}
    for body in run.bodies:
        x = run.get(step, f"body_{body}/x").reshape(-1, 2)
        v = run.get(step, f"body_{body}/v").reshape(-1, 2)
        tri = run.h5[f"body_{body}/triangles"][()]
        m = run.motion(body)
        for a, b, c in tri:
            pts = [tuple(x[a]), tuple(x[b]), tuple(x[c])]
            for img in run.images(pts):
                xs, ys = [p[0] for p in img], [p[1] for p in img]
                for comp, fam in enumerate((run.fam["u"], run.fam["v"])):
                    name = "uv"[comp]
                    i0 = max(np.searchsorted(fam.ex, min(xs), "right") - 1, 0)
                    i1 = min(np.searchsorted(fam.ex, max(xs), "left"), fam.ni)
                    j0 = max(np.searchsorted(fam.ey, min(ys), "right") - 1, 0)
                    j1 = min(np.searchsorted(fam.ey, max(ys), "left"), fam.nj)
                    for j in range(j0, j1):
                        for i in range(i0, i1):
                            poly = clip_box(img, fam.ex[i], fam.ex[i + 1], fam.ey[j], fam.ey[j + 1])
                            if len(poly) < 3:
                                continue
                            area, cen = area_centroid(poly)
                            if area <= 0:
                                continue
                            if m is not None:  # analytic rigid velocity at the centroid
                                w = 2 * math.pi * m.get("frequency", 0.0)
                                s, co = math.sin(w * t + m.get("phase", 0.0)), math.cos(w * t + m.get("phase", 0.0))
                                c0 = [m.get("center", [0, 0])[k] + m.get("velocity", [0, 0])[k] * t
                                      + m.get("amplitude", [0, 0])[k] * s for k in range(2)]
                                dth = m.get("omega", 0.0) + m.get("angle", 0.0) * w * co
                                # the image's centroid, shifted back to the body's own position
                                back = (img[0][0] - pts[0][0], img[0][1] - pts[0][1])
                                q = (cen[0] - back[0] - c0[0], cen[1] - back[1] - c0[1])
                                vel = (m.get("velocity", [0, 0])[0] + m.get("amplitude", [0, 0])[0] * w * co - dth * q[1],
                                       m.get("velocity", [0, 0])[1] + m.get("amplitude", [0, 0])[1] * w * co + dth * q[0])
                                val = vel[comp]
                            else:  # the FE field, linear on the triangle
                                n = barycentric(img, cen)
                                val = n[0] * v[a][comp] + n[1] * v[b][comp] + n[2] * v[c][comp]
                            e = out[name].setdefault(i + fam.ni * j, [0.0, 0.0])
                            e[0] += area
                            e[1] += area * val
    return out


def body_area(run, step):
    total = 0.0
    for body in run.bodies:
        x = run.get(step, f"body_{body}/x").reshape(-1, 2)
        for a, b, c in run.h5[f"body_{body}/triangles"][()]:
            total += 0.5 * ((x[b, 0] - x[a, 0]) * (x[c, 1] - x[a, 1]) - (x[c, 0] - x[a, 0]) * (x[b, 1] - x[a, 1]))
    return total


# ---- the checks: each yields (step, relative error, note) -----------------------------------
def check_areas(run, steps):
    for s in steps:
        area = body_area(run, s)
        for c in "uv":
            idx = run.get(s, f"solid_{c}/index", int)
            alpha = run.get(s, f"solid_{c}/alpha")
            total = float(np.sum(alpha * run.fam[c].volume(idx)))
            yield s, abs(total - area) / area, f"{c}: sum alpha|V| = {total:.15g}, area {area:.15g}"


def check_fractions(run, steps):
    for s in steps:
        exact = exact_faces(run, s)
        for c in "uv":
            idx = run.get(s, f"solid_{c}/index", int)
            alpha = dict(zip(idx.tolist(), run.get(s, f"solid_{c}/alpha")))
            fam = run.fam[c]
            worst, note = 0.0, ""
            for face in set(alpha) | set(exact[c]):
                want = min(1.0, exact[c].get(face, [0.0])[0] / fam.volume(face))
                err = abs(alpha.get(face, 0.0) - want)
                if err >= worst:
                    worst, note = err, f"{c}-face {face}: alpha {alpha.get(face, 0.0):.15g}, exact {want:.15g}"
            yield s, worst, note


def check_solid_velocity(run, steps):
    for s in steps:
        vmax = max(np.abs(run.get(s, f"body_{b}/v")).max(initial=0.0) for b in run.bodies)
        exact = exact_faces(run, s)
        for c in "uv":
            idx = run.get(s, f"solid_{c}/index", int)
            vel = run.get(s, f"solid_{c}/velocity")
            worst, note = 0.0, ""
            for face, u in zip(idx.tolist(), vel):
                a, au = exact[c].get(face, [0.0, 0.0])
                if a <= 0:
                    worst, note = math.inf, f"{c}-face {face} has no solid here"
                    continue
                err = abs(u - au / a) / vmax
                if err >= worst:
                    worst, note = err, f"{c}-face {face}: u_s {u:.15g}, exact {au / a:.15g}"
            yield s, worst, note + f" (max node speed {vmax:.3g})"


def check_solid_forces(run, steps):
    for s in steps:
        nodal = np.zeros(2)
        for b in run.bodies:
            f = run.get(s, f"body_{b}/reaction").reshape(-1, 2)
            nodal += f.sum(axis=0)
        fluid, scale = np.zeros(2), 0.0
        for k, c in enumerate("uv"):
            idx = run.get(s, f"solid_{c}/index", int)
            fs = run.get(s, f"solid_{c}/fs")
            vol = run.fam[c].volume(idx)
            fluid[k] = np.sum(fs * vol)
            scale += np.sum(np.abs(fs) * vol)
        if scale == 0:
            yield s, math.inf, "no interaction force at all: nothing checked"
            continue
        err = np.abs(nodal + fluid).max() / scale
        yield s, err, f"sum F_a = ({nodal[0]:.6g}, {nodal[1]:.6g}), sum f_s|V| = ({fluid[0]:.6g}, {fluid[1]:.6g})"


def check_fiber_velocity(run, steps, field, on_markers):
    """on_markers False: the fluid's samples u^n equal the field on their faces (the fluid holds
    it; without this the marker check would test nothing). True: U(X^n) equals it at the markers."""
    u0, g = np.array(field[:2]), np.array(field[2:]).reshape(2, 2)
    def exact(x, y):
        return u0 + g @ np.array([x, y])
    for s in steps:
        if not any(f"fiber_{f}/u" in run.h5[s] for f in run.fibers):
            continue  # step 0: no samples yet
        scale = 0.0
        for f in run.fibers:
            X = run.get(s, f"fiber_{f}/x").reshape(-1, 2)
            scale = max([scale] + [np.abs(exact(*p)).max() for p in X])
        worst, note = 0.0, ""
        if not on_markers:
            for k, c in enumerate("uv"):
                for face, val in zip(run.get(s, f"samples_{c}/index", int), run.get(s, f"samples_{c}/value")):
                    want = exact(*run.fam[c].position(face))[k]
                    err = abs(val - want) / scale
                    if err >= worst:
                        worst, note = err, f"fluid sample {c}-face {face}: {val:.15g}, field {want:.15g}"
            yield s, worst, note
            continue
        for f in run.fibers:
            X = run.get(s, f"fiber_{f}/x").reshape(-1, 2)
            U = run.get(s, f"fiber_{f}/u").reshape(-1, 2)
            for m, (p, u) in enumerate(zip(X, U)):
                err = np.abs(u - exact(*p)).max() / scale
                if err >= worst:
                    worst, note = err, (f"fiber {f} marker {m} at ({p[0]:.6g}, {p[1]:.6g}): "
                                        f"U = ({u[0]:.15g}, {u[1]:.15g})")
        yield s, worst, note


def check_fiber_forces(run, steps):
    hx, hy = run.xf[1] - run.xf[0], run.yf[1] - run.yf[0]
    for s in steps:
        spread = np.array([run.get(s, f"spread_{c}/force").sum() * hx * hy for c in "uv"])
        markers, scale = np.zeros(2), 0.0
        for f in run.fibers:
            F = run.get(s, f"fiber_{f}/force").reshape(-1, 2)
            w = np.full(len(F), run.h5[f"fiber_{f}"].attrs["ds"])
            w[0] *= 0.5
            w[-1] *= 0.5
            markers += (F * w[:, None]).sum(axis=0)
            scale += (np.abs(F) * w[:, None]).sum()
        if scale == 0:
            continue  # step 0: the feedback starts on step 1
        err = np.abs(spread + markers).max() / scale
        yield s, err, f"sum f_f hx hy = ({spread[0]:.6g}, {spread[1]:.6g}), sum F w = ({markers[0]:.6g}, {markers[1]:.6g})"


def check_root_loads(run, steps):
    for s in steps:
        for f in run.fibers:
            if f"fiber_{f}/root_pose" not in run.h5[s]:
                continue
            p = run.get(s, f"fiber_{f}/root_pose")[:2]
            load = run.get(s, f"fiber_{f}/root_load")
            force, moment, length = np.zeros(2), 0.0, math.inf
            for b in run.bodies:
                nodal = run.get(s, f"body_{b}/root_force").reshape(-1, 2)
                if not nodal.size:
                    continue
                x = run.get(s, f"body_{b}/x").reshape(-1, 2)
                used = np.nonzero(np.abs(nodal).sum(axis=1))[0]
                if len(used) > 1:
                    length = min(length, np.linalg.norm(x[used[0]] - x[used[-1]]))
                r = x - p
                force += nodal.sum(axis=0)
                moment += float(np.sum(r[:, 0] * nodal[:, 1] - r[:, 1] * nodal[:, 0]))
            scale = np.abs(load[:2]).max() + abs(load[2]) / length
            if scale == 0:  # before the fiber's first step: no load, and no nodal force either
                if np.abs(force).max() > 0 or moment != 0:
                    yield s, math.inf, f"fiber {f}: nodal forces without a root load"
                continue
            err = max(np.abs(force - load[:2]).max(), abs(moment - load[2]) / length) / scale
            yield s, err, (f"fiber {f}: load ({load[0]:.6g}, {load[1]:.6g}, M {load[2]:.6g}), nodal "
                           f"({force[0]:.6g}, {force[1]:.6g}, M {moment:.6g})")
        yield from check_root_masses(run, s)


def check_root_masses(run, s):
    """Sum over the nodes of the lumped root masses = sum over the fibers, and the same first
    moment about the origin (the lumping (1 - s) m at a, s m at b keeps the root point)."""
    fib, fib_moment = np.zeros(3), np.zeros((2, 3))
    for f in run.fibers:
        if f"fiber_{f}/root_pose" not in run.h5[s] or f"fiber_{f}/root_mass" not in run.h5[s]:
            continue
        m = run.get(s, f"fiber_{f}/root_mass")
        p = run.get(s, f"fiber_{f}/root_pose")[:2]
        fib += m
        fib_moment += np.outer(p, m)
    nodal, nodal_moment = np.zeros(3), np.zeros((2, 3))
    for b in run.bodies:
        if f"body_{b}/root_mass" not in run.h5[s]:
            continue
        mm = run.get(s, f"body_{b}/root_mass").reshape(-1, 3)
        x = run.get(s, f"body_{b}/x").reshape(-1, 2)
        nodal += mm.sum(axis=0)
        nodal_moment += x.T @ mm
    scale = np.abs(fib).max()
    if scale == 0:
        return
    err = max(np.abs(nodal - fib).max(), np.abs(nodal_moment - fib_moment).max()) / scale
    yield s, err, f"root mass: fibers {fib}, nodes {nodal}"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("run_dir")
    p.add_argument("--check", action="append", required=True,
                   choices=["areas", "fractions", "solid-velocity", "solid-forces",
                            "fluid-field", "fiber-velocity", "fiber-forces", "root-loads"])
    p.add_argument("--tol", type=float, default=1e-12)
    p.add_argument("--from-step", type=int, default=0)
    p.add_argument("--field", default="0,0,0,0,0,0")
    a = p.parse_args()
    run = Run(a.run_dir)
    steps = [s for s in run.steps if run.h5[s].attrs["step"] >= a.from_step]
    field = [float(v) for v in a.field.split(",")]
    checks = {"areas": lambda: check_areas(run, steps),
              "fractions": lambda: check_fractions(run, steps),
              "solid-velocity": lambda: check_solid_velocity(run, steps),
              "solid-forces": lambda: check_solid_forces(run, steps),
              "fluid-field": lambda: check_fiber_velocity(run, steps, field, False),
              "fiber-velocity": lambda: check_fiber_velocity(run, steps, field, True),
              "fiber-forces": lambda: check_fiber_forces(run, steps),
              "root-loads": lambda: check_root_loads(run, steps)}
    failed = False
    for name in a.check:
        rows = list(checks[name]())
        if not rows:
            print(f"FAIL: {name}: nothing to check in {len(steps)} dumped steps")
            failed = True
            continue
        step, worst, note = max(rows, key=lambda r: r[1])
        ok = worst <= a.tol
        failed |= not ok
        print(f"{'ok' if ok else 'FAIL'}: {name}: worst relative error {worst:.3e} (tolerance "
              f"{a.tol:g}) over {len(rows)} checks in {len(steps)} steps; worst at {step}: {note}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
