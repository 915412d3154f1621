"""2D rigid-body dynamics of one body under the fluid's nodal reaction, gravity and nothing else.

Mass and inertia are the excess ones, m = (rho_s - rho_f) A and J = (rho_s - rho_f) I_c (A the
mesh's area, I_c its polar moment about its centroid C, exact for the triangles): the fluid fills
the body's region and carries rho_f of its mass on the grid (DESIGN.md Sec. 4.2). The coupler's
nodal forces F_a (on the solid, at the nodes of x^n) give the force F = sum_a F_a and the torque
T = sum_a (x_a - C^n) x F_a. They are the reaction of the fluid's velocity correction over the
step, an impulse F dt within it (as solid/'s Newmark step takes them), gravity a constant load:

  m (V^(n+1) - V^n) = dt (F + m g),          C^(n+1) = C^n + dt/2 (V^n + V^(n+1))
  J (W^(n+1) - W^n) = dt T,                  th^(n+1) = th^n + dt/2 (W^n + W^(n+1))

the trapezoidal rule (Newmark beta = 1/4, gamma = 1/2) for the pose, second order; the nodes
x_a = C + R(th) (X_a - C_ref), v_a = V + W e_z x (x_a - C).

With coupled iterations the coupler also sends the nodal velocities w the fluid's forcing used;
about them the reaction is F_c(v) ~ F_c - M_f (v - w)/dt (M_f the fluid's mass matrix in the
body). For a rigid v this is F - m_f (V - V_w)/dt and T - J_f (W - W_w)/dt, with m_f = rho_f A,
J_f = rho_f I_c and (V_w, W_w) the rigid motion of the same momentum as w: the step solves with
the whole mass rho_s A (the term vanishes at convergence, v = w).

Fibers rooted on the body (protocol version 7): the coupler's root_mass gives a 2 x 2 block m_a
at some nodes, which carry -m_a (v_a^(n+1) - v_a^n)/dt besides the forces (the fibers' inertia,
taken implicitly). With v_a = G_a (V, W), G_a = [[1, 0, -r_y], [0, 1, r_x]], the step solves the
3 x 3 system (diag(m, m, J) + sum_a G_a^T m_a G_a) (V, W)^(n+1) = (momenta above)
+ sum_a G_a^T m_a G_a (V, W)^n."""
import math

import numpy as np

from wire import Failure


def geometry(x, tri):
    """Area A, centroid C, polar moment I_c = int |x - C|^2 dA, lumped node weights int N_a dA,
    all exact for linear triangles."""
    p = x.reshape(-1, 2)
    a, b, c = p[tri[:, 0]], p[tri[:, 1]], p[tri[:, 2]]
    area = 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1]))
    A = area.sum()
    C = (area[:, None] * (a + b + c) / 3).sum(axis=0) / A
    a, b, c = a - C, b - C, c - C
    sq = lambda u, v: (u * v).sum(axis=1)  # noqa: E731
    I = (area / 6 * (sq(a, a) + sq(b, b) + sq(c, c) + sq(a, b) + sq(b, c) + sq(c, a))).sum()
    w = np.zeros(len(p))
    for k in range(3):
        np.add.at(w, tri[:, k], area / 3)
    return A, C, I, w


class RigidBody:
    def __init__(self, spec, fluid_density, gravity):
        self.name, self.fixed, self.tri = spec.name, spec.fixed, spec.tri
        self.x_ref = spec.x.reshape(-1, 2).copy()
        A, C, I, self.w = geometry(spec.x, spec.tri)
        if not A > 0:
            raise Failure(f"body '{self.name}': its mesh ({spec.source}) has zero area: a body of "
                          "zero mass has no dynamics")
        self.area, self.c_ref, self.inertia_area = A, C, I
        self.rho_f = fluid_density
        rho_e = 0.0 if spec.fixed else spec.density - fluid_density
        self.m, self.J = rho_e * A, rho_e * I            # excess mass and inertia
        self.m_f, self.J_f = fluid_density * A, fluid_density * I
        self.g = np.array(gravity) if spec.gravity else np.zeros(2)
        self.r_ref = self.x_ref - C                      # node offsets from C in the reference
        # The state at t^n: centre, angle, velocity, angular velocity.
        self.C, self.th = C.copy(), 0.0
        self.V = np.zeros(2) if spec.fixed else np.array(spec.velocity, dtype=float)
        self.W = 0.0 if spec.fixed else float(spec.angular_velocity)
        self.F, self.T = np.zeros(2), 0.0                # the last step's fluid force and torque

    def save(self):
        return (self.C.copy(), self.th, self.V.copy(), self.W, self.F.copy(), self.T)

    def restore(self, s):
        self.C, self.th, self.V, self.W, self.F, self.T = s[0].copy(), s[1], s[2].copy(), s[3], s[4].copy(), s[5]

    def offsets(self):
        c, s = math.cos(self.th), math.sin(self.th)
        r = self.r_ref
        return np.column_stack((c * r[:, 0] - s * r[:, 1], s * r[:, 0] + c * r[:, 1]))

    def nodes(self):
        """(x, v) of the nodes at the current state, interleaved."""
        r = self.offsets()
        x = self.C + r
        v = self.V + self.W * np.column_stack((-r[:, 1], r[:, 0]))
        return x.ravel(), v.ravel()

    def rigid_part(self, w):
        """(V_w, W_w): the rigid motion with the same linear and angular momentum as the nodal
        velocities w over the body (lumped weights for the momentum; exact for rigid w)."""
        w = w.reshape(-1, 2)
        r = self.offsets()
        Vw = (self.w[:, None] * w).sum(axis=0) / self.area
        Lw = (self.w * (r[:, 0] * w[:, 1] - r[:, 1] * w[:, 0])).sum()
        lumped = (self.w * (r * r).sum(axis=1)).sum()
        return Vw, Lw / lumped

    def advance(self, dt, force, velocity, root_mass=None):
        """One step from the current state (t^n) with the nodal forces (on the solid) at x^n."""
        if self.fixed:
            self.F, self.T = self.resultant(force)
            return
        F, T = self.resultant(force)
        self.F, self.T = F, T
        m, J = self.m, self.J
        p = m * self.V + dt * (F + m * self.g)          # momentum after the step, without the
        L = J * self.W + dt * T                         # linearised reaction
        if velocity is not None and velocity.size:
            Vw, Ww = self.rigid_part(velocity)
            p, L = p + self.m_f * Vw, L + self.J_f * Ww
            m, J = m + self.m_f, J + self.J_f
        if not (m > 0 and J > 0):
            raise Failure(f"body '{self.name}' has no positive mass in the explicit step (rho_s "
                          f"<= rho_f: excess mass {self.m:g}); turn on coupled iterations "
                          "([coupler.iterations] max > 1), in which the fluid's reaction is "
                          "linearised and the body carries its whole mass rho_s A")
        if root_mass is not None and root_mass.size:
            A = np.diag([m, m, J])
            b = np.array([p[0], p[1], L])
            r = self.offsets()
            blocks = root_mass.reshape(-1, 3)
            for a in np.nonzero(np.abs(blocks).sum(axis=1))[0]:
                mxx, mxy, myy = blocks[a]
                G = np.array([[1.0, 0.0, -r[a, 1]], [0.0, 1.0, r[a, 0]]])
                GmG = G.T @ np.array([[mxx, mxy], [mxy, myy]]) @ G
                A += GmG
                b += GmG @ np.array([self.V[0], self.V[1], self.W])
            sol = np.linalg.solve(A, b)
            V1, W1 = sol[:2], float(sol[2])
        else:
            V1, W1 = p / m, L / J
        self.C = self.C + 0.5 * dt * (self.V + V1)
        self.th += 0.5 * dt * (self.W + W1)
        self.V, self.W = V1, W1

    def resultant(self, force):
        if force is None or force.size == 0:
            return np.zeros(2), 0.0
        f = force.reshape(-1, 2)
        r = self.offsets()
        return f.sum(axis=0), float((r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]).sum())
