#!/usr/bin/python3
"""[fluid] body_viscosity = "none" takes the fluid's viscosity out of elastic bodies only.

  rigid_body_viscosity.py --cwd DIR --bin BIN --elastic SCENE --free DISK -- MPIEXEC...

1. A fixed rigid block under Couette flow (runs/sub-cell-wall's set-up at lambda = 2, its top in
   the middle of a cell, 300 steps): run with "none" and with "kelvin-voigt", every CSV and .h5
   dataset must be the same bit for bit (a rigid body keeps the fluid's viscosity; when the
   correction also took the block's cut faces, its wall moved a third of a cell into the block).
2. The same for DISK (a free rigid body moved by solid-rigid, a body of kind 0 that says it is
   rigid) cut to 0.05.
3. The control: SCENE (an elastic layer) cut to 0.05, with "none" and with "kelvin-voigt", must
   differ, so that the correction is still applied where it belongs.
Exits 1 naming what went wrong.
"""
import argparse
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_outputs import compare_dirs  # noqa: E402

N, DT, LAMBDA = 16, 1e-3, 2.0
RIGID = f"""[scene]
name = "rigid-block"
[time]
dt = {DT}
t_end = {300 * DT}
[output]
interval = {100 * DT}
[fluid]
density = 1.0
viscosity = {LAMBDA / N**2 / DT!r}
diffusion = "implicit"
body_viscosity = "BODY_VISCOSITY"
[fluid.grid]
cells = [4, {N}]
size = [0.25, 1.0]
[fluid.boundary]
left = {{ type = "periodic" }}
right = {{ type = "periodic" }}
bottom = {{ type = "wall" }}
top = {{ type = "wall", velocity = 1.0 }}
[solid]
[[solid.body]]
name = "block"
kind = "rigid"
rectangle = {{ origin = [0.0, 0.0], size = [0.25, {4.5 / N!r}], cells = [2, 4] }}
"""


def run(mpiexec, bin_dir, text, cwd, name, solid="solid"):
    scene = os.path.join(cwd, name + ".toml")
    with open(scene, "w") as f:
        f.write(text)
    out = os.path.join(cwd, name)
    cmd = list(mpiexec)
    for k, p in enumerate(["fluid", solid, "coupler"]):
        if k:
            cmd.append(":")
        cmd += ["-n", "1", os.path.join(bin_dir, p), scene, "--out-dir", out, "--overwrite"]
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"rigid_body_viscosity: the run of {scene} failed (exit {r.returncode}):\n"
                 f"{r.stderr[-2000:]}")
    return out


def short(scene):
    """The scene's text cut to t = 0.05, its relative mesh paths made absolute."""
    with open(scene) as f:
        text = f.read()
    text = re.sub(r"\nt_end = [0-9.e+-]+", "\nt_end = 0.05", text)
    text = re.sub(r"\ninterval = [0-9.e+-]+", "\ninterval = 0.025", text)
    here = os.path.dirname(os.path.abspath(scene))
    return re.sub(r'\nmesh = "([^"/][^"]*)"',
                  lambda m: f'\nmesh = "{os.path.normpath(os.path.join(here, m.group(1)))}"', text)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cwd", required=True)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--elastic", required=True)
    ap.add_argument("--free", required=True)
    ap.add_argument("mpiexec", nargs="+")
    a = ap.parse_args()
    os.makedirs(a.cwd, exist_ok=True)

    def same(what, texts, solid="solid"):
        """Run the body with "none" and with "kelvin-voigt" (texts): the same bit for bit."""
        outs = [run(a.mpiexec, a.bin, t, a.cwd, f"{what.replace(' ', '-')}-{v}", solid)
                for v, t in zip(("none", "kelvin-voigt"), texts)]
        diff, compared = compare_dirs(*outs)
        if diff:
            sys.exit(f"rigid_body_viscosity: a {what} with body_viscosity = \"none\" and "
                     f"\"kelvin-voigt\": {diff}; a rigid body must keep the fluid's viscosity")
        print(f"rigid_body_viscosity: {what}, {compared} files and datasets the same")

    same("rigid block", [RIGID.replace("BODY_VISCOSITY", v) for v in ("none", "kelvin-voigt")])
    # The free disk: its scene without the key (the default "none") and with "kelvin-voigt".
    text = short(a.free)
    if "body_viscosity" in text or 'diffusion = "implicit"' not in text:
        sys.exit(f"rigid_body_viscosity: {a.free} should name Crank-Nicolson and no body_viscosity")
    same("free rigid disk",
         [text, text.replace('diffusion = "implicit"',
                             'diffusion = "implicit"\nbody_viscosity = "kelvin-voigt"')],
         solid="solid-rigid")

    text = short(a.elastic)
    if 'body_viscosity = "none"' not in text:
        sys.exit(f"rigid_body_viscosity: {a.elastic} does not name body_viscosity = \"none\"")
    outs = [run(a.mpiexec, a.bin,
                text.replace('body_viscosity = "none"', f'body_viscosity = "{v}"'),
                a.cwd, f"elastic-{v}") for v in ("none", "kelvin-voigt")]
    diff, _ = compare_dirs(*outs)
    # A difference in the data ("X differs", a CSV's with its first line), not in which files
    # the folders hold.
    if not diff or not re.search(r" differs(: line |: \d+ lines against |$)", diff):
        sys.exit("rigid_body_viscosity: an elastic layer with body_viscosity = \"none\" against "
                 f"\"kelvin-voigt\": {diff or 'the same results'}; the correction must change them")
    print(f"rigid_body_viscosity: elastic layer differs as it should ({diff})")


if __name__ == "__main__":
    main()
