#!/usr/bin/python3
"""The glycocalyx channel's scene (paper Sec. 5.2, Table 4; runs/glycocalyx/README.md): the text
of one variant, or, run as a script, scene.toml (the elastic wall with fibers).

Non-dimensional by the friction velocity u_tau and the channel width H: rho_f = 1, mu = 1/Re_tau,
the driving -dp/dx = (2 tau_w / H) sin(2 pi t / T) with tau_w = 1, T = 1.2. The domain
[0, 1] x [0, 3/4] (periodic in x, a wall at y = 0, symmetry at y = 3H/4), 128 x 96 cells. The wall
layer (wall.geo): mean thickness H/4, surface y = H/4 + delta cos(2 pi x), so the fluid's half
channel is H/2 wide on average. Sixteen fibers clamped at right angles on the surface at the
middle of every fourth surface edge. Probes: C on the wall's surface at x = 1/2 (the trough,
[[coupler.surface_probe]] and [[solid.body.probe]]), D on the centre line above it."""
import argparse
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
GEO = os.path.join(HERE, "wall.geo")

RE_TAU = 25.0
PERIOD = 1.2
TAU_W = 1.0
H = 1.0
L = 1.0
T_WALL = 0.25       # the wall layer's mean thickness
DELTA = 0.05        # the amplitude of its cosine surface
NX, NY = 64, 16     # wall.geo's quadrilaterals along and across (1 105 nodes, 2 048 triangles)
FIBERS = 16
FIBER = {"length": 0.125, "segments": 62, "density": 1.1, "bending": 1e-4}
KAPPA = 1e5
DT = 1e-4
CELLS = (128, 96)
E_WALL = 10.0
NU_WALL = 0.2
RHO_WALL = 10.0
# Point C: the wall's surface at the trough x = L/2, where its normal is vertical (the paper: "the
# normal direction at C is perpendicular to the flow direction"), halfway between two fibers;
# point D on the centre line (the symmetry plane y = 3H/4) above it, in the top row of cells.
C_X = 0.5


def surface_y(x):
    """y of the wall's surface polyline (through the nodes at x = i L / NX on the cosine)."""
    u = (x % L) / L * NX
    i = math.floor(u)
    s = u - i
    y0 = T_WALL + DELTA * math.cos(2 * math.pi * i / NX)
    y1 = T_WALL + DELTA * math.cos(2 * math.pi * (i + 1) / NX)
    return (1 - s) * y0 + s * y1


def roots():
    """The fibers' root points: the middle of surface edge 4k + 2 (k = 0 .. 15)."""
    xs = [(4 * k + 2.5) * L / NX for k in range(FIBERS)]
    return [(x, surface_y(x)) for x in xs]


def scene(name, elastic=True, fibers=True, periods=10.0, e_wall=E_WALL, dt=DT, cells=CELLS,
          interval=0.05, extra=""):
    """The scene text of one variant."""
    nx, ny = cells
    body = "elastic" if elastic else "rigid"
    text = f"""# Glycocalyx channel (paper Sec. 5.2): {body} wavy wall, {'16 fibers' if fibers else 'no fibers'}
# (runs/glycocalyx/README.md; written by runs/glycocalyx/make_scene.py)
[scene]
name = "{name}"

[time]
dt = {dt!r}
t_end = {periods * PERIOD!r}

[output]
interval = {interval!r}

[fluid]
density = 1.0
viscosity = {1 / RE_TAU!r}
diffusion = "implicit"

[fluid.grid]
cells = [{nx}, {ny}]
size = [{L!r}, {0.75 * H!r}]

[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ type = "slip" }}

[fluid.forcing]
oscillating = [{2 * TAU_W / H!r}, 0.0]
period = {PERIOD!r}

[fluid.diagnostics]
flow_rate = [0.5]

[[fluid.probes]]
name = "D"
at = [{C_X!r}, {0.75 * H - 0.5 * 0.75 * H / ny!r}]


[solid]

[[solid.body]]
name = "wall"
mesh = "{GEO}"
mesh_parameters = "T = {T_WALL!r}, delta = {DELTA!r}, nx = {NX}, ny = {NY}"
"""
    if elastic:
        text += f"""
[[solid.body.material]]
model = "saint-venant-kirchhoff"
density = {RHO_WALL!r}
youngs_modulus = {e_wall!r}
poisson_ratio = {NU_WALL!r}

[[solid.body.constraint]]
boundary = "wall"
type = "fixed"

[[solid.body.probe]]
name = "C"
point = [{C_X!r}, {surface_y(C_X)!r}]

[[solid.body.constraint]]
boundary = "right"
type = "periodic"
partner = "left"
shift = [{L!r}, 0.0]
"""
    else:
        text += """kind = "rigid"
"""
    if fibers:
        # The explicit bending limit dt <= ds^2 sqrt(rho' / (12 gamma)) (fiber/README.md):
        # 1.23e-4 for the paper's fibers, sub-steps for lighter ones.
        ds = FIBER["length"] / FIBER["segments"]
        limit = ds * ds * math.sqrt(FIBER["density"] / (12 * FIBER["bending"]))
        text += f"""
[fiber]
substeps = {max(1, math.ceil(dt / limit))}
"""
        for k, (x, y) in enumerate(roots()):
            text += f"""
[[fiber.fiber]]
name = "f{k:02d}"
length = {FIBER['length']!r}
segments = {FIBER['segments']}
density = {FIBER['density']!r}
bending = {FIBER['bending']!r}
angle = 90

[fiber.fiber.root]
kind = "attached"
body = "wall"
point = [{x!r}, {y!r}]
"""
        text += f"""
[coupler]
kappa = {KAPPA!r}
"""
    text += f"""
[[coupler.surface_probe]]
name = "C"
body = "wall"
point = [{C_X!r}, {surface_y(C_X)!r}]
"""
    return text + extra


if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", default=os.path.join(HERE, "scene.toml"))
    a = p.parse_args()
    text = scene("glycocalyx").replace(f'"{GEO}"', '"wall.geo"')
    with open(a.out, "w") as f:
        f.write(text)
