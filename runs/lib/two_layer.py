"""The oscillating two-layer channel (Sugiyama et al., JCP 230 (2011) 596), shared by
runs/two-layer-channel and runs/equal-density: its set-up, its scene and the exact periodic
solution of the layer the immersed-solid method models (runs/two-layer-channel/README.md)."""
import numpy as np

import fluidout

# Set-up of Sugiyama et al. (other-cases.md) except rho_s: with rho_s = rho_f the layer has no
# excess mass and the staggered coupling is unstable; the exact solution holds for any rho_s,
# so the two-layer case takes rho_s = 2 rho_f.
V0, OMEGA, RHO_F, MU, G, K_BULK, RHO_S = 1.0, np.pi, 1.0, 1.0, 5.0, 500.0, 2.0
PERIOD = 2 * np.pi / OMEGA


def exact(y, t, h, mu_s=MU, rho_s=RHO_S):
    """Exact periodic u(y, t) of a Kelvin-Voigt layer (shear stress G xi_y + mu_s xi_ty) under the
    fluid; mu_s = 0 is the purely elastic layer of other-cases.md. With G* = G + i omega mu_s:
    solid X = A sin(ks y), ks = omega sqrt(rho_s / G*); fluid U = B sinh(k (y - h)) +
    C cosh(k (y - h)), k = sqrt(i omega rho_f / mu); u = i omega X in the solid;
    C = i omega A sin(ks h) (velocity continuity), mu k B = G* ks A cos(ks h) (traction),
    U(1) = -i V0 (wall V0 sin(omega t) = Re[-i V0 exp(i omega t)])."""
    gs = G + 1j * OMEGA * mu_s
    ks = OMEGA * np.sqrt(rho_s / gs)
    k = np.sqrt(1j * OMEGA * RHO_F / MU)
    L = 1.0 - h
    a = -1j * V0 / (1j * OMEGA * np.sin(ks * h) * np.cosh(k * L) +
                    gs * ks * np.cos(ks * h) / (MU * k) * np.sinh(k * L))
    b = gs * ks * a * np.cos(ks * h) / (MU * k)
    c = 1j * OMEGA * a * np.sin(ks * h)
    y = np.asarray(y, dtype=float)
    U = np.where(y < h, 1j * OMEGA * a * np.sin(ks * y),
                 b * np.sinh(k * (y - h)) + c * np.cosh(k * (y - h)))
    return np.real(np.outer(np.exp(1j * OMEGA * np.atleast_1d(t)), U))


def scene(name, n, h, dt, t_end, rho_s=RHO_S, body_viscosity=None):
    """The scene on n cells across, the layer's top at y = h; body_viscosity: the fluid's key of
    that name ("none": a purely elastic layer, or "kelvin-voigt"), None for its default."""
    # The layer's top moves up to ~0.15 in x: a period of 0.25 keeps it within one period of
    # the box (the footprint of a body displaced by more than a period is not wrapped twice).
    width = 0.25
    nx = max(4, n // 4)
    ns = max(1, int(round(h * n)))
    return f"""[scene]
name = "{name}"
[time]
dt = {dt}
t_end = {t_end}
[output]
interval = {PERIOD / 16}
[fluid]
density = {RHO_F}
viscosity = {MU}
diffusion = "implicit"
{f'body_viscosity = "{body_viscosity}"' if body_viscosity else ""}
[fluid.grid]
cells = [{nx}, {n}]
size = [{width!r}, 1.0]
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall", amplitude = {V0}, omega = {OMEGA!r} }}
[solid]
[[solid.body]]
name = "layer"
rectangle = {{ origin = [0.0, 0.0], size = [{width!r}, {h!r}], cells = [{nx}, {ns}] }}
[[solid.body.material]]
model = "neo-hookean"
density = {rho_s}
shear_modulus = {G}
bulk_modulus = {K_BULK}
[[solid.body.constraint]]
boundary = "bottom"
type = "fixed"
[[solid.body.constraint]]
boundary = "left"
type = "periodic"
partner = "right"
"""


def rms_error(folder, h, t_end, rho_s=RHO_S, mu_s=MU):
    """The x-averaged u of the last period against the exact solution: (worst phase's RMS over
    y / V0, max error / V0, phases, y, times, profiles)."""
    yc, ts, us = fluidout.mean_u(folder, since=t_end - PERIOD)
    ex = exact(yc, ts, h, mu_s, rho_s)
    rms = np.sqrt(np.mean((us - ex) ** 2, axis=1)) / V0
    return float(rms.max()), float(np.max(np.abs(us - ex)) / V0), yc, ts, us
