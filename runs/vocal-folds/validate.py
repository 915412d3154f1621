#!/usr/bin/python3
"""Vocal folds (paper Sec. 5.1): two mirrored two-layer M5 folds in a channel, frictionless
contact between them.

The coupled runs use the set-up validated in README.md unless told otherwise: neo-Hookean folds,
a contact plane at each wall, the fluid sub-cycled (up to 4 substeps), third-order upwind
convection, the scene's Newmark gamma = 0.55. The paper's own choices, with which the runs do
not last through the closures to t = 12 (README), are one option each: --material saint-venant-kirchhoff,
--no-wall-planes, --substeps 0, --convection central (with --upwind 0.2, the blend that keeps
central convection stable in the jet), --newmark-gamma 0.5.

--modes: the first three eigenfrequencies and mode shapes of one fold (paper Eq. 28; the paper
  finds 1.85, 4.12, 5.45 for its geometry) and of the pair, the pair's modes as mirror-symmetric
  and antisymmetric combinations; modes.png.
--short: h = 0 (the folds touch at t = 0) on a coarse grid through the first contact episodes;
  fails when contact in the flow breaks (Newton, penetration) or the run stops.
--run H: one coupled run at clearance h/D = H (--grid paper|coarse, --t-end T (default 12),
  --impulsive: no inflow ramp, --upwind B, --p-sub P: a pressure inlet, with the fluid's
  body_divergence = "coupled_step" unless --body-divergence is given).
--sweep: the clearance sweep (paper Sec. 5.1): h = 0, 0.01, 0.02, 0.04, 0.05 with the velocity
  inflow and h = 0 with a pressure inlet (P = 5000), on --grid (default paper) to --t-end
  (default 12) with --upwind (default 0; 0.2 with --convection central); with --modes. A run of
  the identical scene already there is used (finished, failed with an ERROR in its log, or still
  running: what it wrote so far), the others are run (--no-run: none is). Per run: point B's
  u_y, its spectrum over t >= 1, the dominant frequency and the nearest eigenfrequency, the
  amplitude, contact, forces and impulses; spectra.png and displacement.png (Fig. 13), frequency.png,
  trajectories.png (Fig. 14), forces_h0.png (Fig. 15), fields.png (Fig. 12); the paper's
  findings reported, only "ran to t_end" judged.
--clearances H,H,...: the sweep's velocity-inflow runs at these clearances only (and no
  pressure-inlet run).
Each choice has its own output folder, nested in this order under OUT: --material neo-hookean
(the default) OUT/neo-hookean; --dt DT (the coupled runs' time step, the paper's 5e-5 by
default) OUT/dt-DT; --wall-planes (default) OUT/planes ([[solid.plane]]: each fold kept on its
side of its wall by a rigid contact plane); --substeps M > 0 OUT/substeps-M ([fluid.substeps]:
up to M fluid steps per coupled step at a CFL number of at most 0.8 each, 0.5 with upwind3;
fluid/README.md); --cover-size LC OUT/cover-LC; --convection upwind3 (default) OUT/upwind3
(fluid.convection, outside the sponge); --predictor OUT/predictor (the solid's Newton starts
each step without active contact at the Newmark step taken with the forces of the step's start,
solid.predictor = "acceleration"); --newmark-gamma G OUT/gamma-G (the solid's Newmark step with
gamma = G and beta = (G + 1/2)^2 / 4 instead of the scene's 0.55; solid.newmark_gamma,
solid/README.md, "Newmark's parameters"; 0.5 is the paper's trapezoidal rule). So the default
runs are in OUT/neo-hookean/planes/substeps-4/upwind3.
--body-viscosity kelvin-voigt: the folds carry the fluid's viscous stress ([fluid]
  body_viscosity; the runs of README.md before the fluid's default became "none" did), outputs
  under OUT/.../body-viscosity-kelvin-voigt.
--body-divergence solid: the fluid in the folds takes their divergence ([fluid] body_divergence;
  README.md, "What stops the pressure inlet"), outputs under OUT/.../body-divergence-solid;
  coupled_step: the share 1 - 1/m^2 of it in a step of m substeps, the pressure of one coupled
  step whatever m (OUT/.../body-divergence-coupled_step). Without the option the velocity
  inflow's runs take the fluid's default ("zero", the paper's), the pressure inlet's
  "coupled_step" (README.md, "What stops the pressure inlet").
--checkpoint-interval T: the coupled runs write a checkpoint every T (`./fsi run SCENE --restart
  RUN` resumes one; the outputs are unchanged).
With no option (`./fsi validate vocal-folds`): --modes, --short and --sweep."""
import argparse
import fcntl
import json
import os
import sys
import time
import warnings

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import job  # noqa: E402
import outputs  # noqa: E402
import series  # noqa: E402
import solidout  # noqa: E402
import h5py  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import at_most, finish, holds, reported  # noqa: E402


def clearance(text):
    """A clearance h/D, for `type=`: the channel is D + h wide, so h > -1. (A negative h > -1
    makes the folds overlap at t = 0, which the solid refuses naming them and the depth.)"""
    try:
        h = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a number, got '{text}'")
    if not np.isfinite(h):
        raise argparse.ArgumentTypeError(f"the clearance h/D must be a finite number, got '{text}'")
    if not h > -1:
        raise argparse.ArgumentTypeError(
            f"the clearance h/D = {text} makes the channel 1 + h = {1 + h:g} D wide, nothing left "
            f"for the flow between the folds 'lower' and 'upper' (each D/2 high): h must be > -1")
    return h


P = cli.parser(__doc__)
P.add_argument("--modes", action="store_true", help="eigenmodes of one fold and of the pair")
P.add_argument("--run", type=clearance, metavar="H", help="one coupled run at clearance h/D = H")
P.add_argument("--grid", choices=("paper", "coarse"), default="paper", help="grid of --run and --sweep")
P.add_argument("--t-end", type=cli.positive, default=None,
               help="end time of --run and of --sweep's runs (default 12)")
P.add_argument("--impulsive", action="store_true", help="--run without the inflow ramp")
P.add_argument("--upwind", type=float, metavar="B", default=None,
               help="--run with fluid.upwind_blend = B (first-order upwind weight outside the sponge); "
                    "--sweep: default 0.2 (0 with --convection upwind3)")
P.add_argument("--p-sub", type=float, metavar="P", default=None,
               help="--run with a pressure inlet: subglottal pressure P (ramped like the inflow), "
                    "pressure 0 at the outlet, instead of the velocity inflow")
P.add_argument("--sweep", action="store_true",
               help="the clearance sweep h = 0, 0.01, 0.02, 0.04, 0.05 (and h = 0 at P = 5000), with --modes")
P.add_argument("--no-run", action="store_true",
               help="--sweep: start no run, process only the runs that are there")
P.add_argument("--material", choices=("saint-venant-kirchhoff", "neo-hookean"),
               default="neo-hookean",
               help="the folds' material (default neo-hookean; saint-venant-kirchhoff: the paper's)")
P.add_argument("--clearances", type=lambda s: [clearance(v) for v in s.split(",")], default=None,
               help="--sweep: only these clearances, velocity inflow")
P.add_argument("--wall-planes", action=argparse.BooleanOptionalAction, default=True,
               help="a rigid contact plane at each wall, for the fold fixed on it (default: on)")
P.add_argument("--dt", type=cli.positive, default=None,
               help="the coupled runs' time step (default: the scene's, the paper's 5e-5)")
P.add_argument("--substeps", type=cli.count, metavar="M", default=4,
               help="the fluid up to M substeps per step, each at a CFL number of at most 0.8 "
                    "(0.5 with --convection upwind3); default 4, 0: one fluid step per step")
P.add_argument("--cover-size", type=cli.positive, metavar="LC", default=None,
               help="the folds' element size within the cover's thickness of the wetted surface "
                    "(fold.geo's lc_cover; default: the element size lc = 0.024 throughout)")
P.add_argument("--convection", choices=("central", "upwind3"), default="upwind3",
               help="the fluid's convection outside the sponge (fluid.convection; default upwind3, "
                    "central: the paper's)")
P.add_argument("--predictor", action="store_true",
               help="the solid's Newton starts at the Newmark step of the step's start forces "
                    "(solid.predictor = \"acceleration\")")
P.add_argument("--newmark-gamma", type=float, metavar="G", default=None,
               help="the solid's Newmark gamma instead of the scene's 0.55 (solid.newmark_gamma; "
                    "beta = (G + 1/2)^2 / 4; 0.5: the paper's trapezoidal rule)")
cli.body_viscosity(P, "the coupled runs")
cli.body_divergence(P, "the coupled runs")
P.add_argument("--checkpoint-interval", type=cli.positive, metavar="T", default=None,
               help="the coupled runs write a checkpoint every T")
ARGS = P.parse_args()
if not (ARGS.modes or ARGS.short or ARGS.run is not None or ARGS.sweep):
    ARGS.modes = ARGS.short = ARGS.sweep = True
if ARGS.sweep:
    ARGS.modes = True  # the sweep compares with the fold's eigenfrequencies and mode shapes
UPWIND3 = ARGS.convection == "upwind3"
# Each variant's outputs in a folder of their own, nested in this order.
OUT = TOP = job.out_dir("vocal-folds")
# The set-up of the defaults: its summary.json is also written to TOP, where `./fsi validate`
# and `./fsi report` look for a case's summary.
DEFAULT_SETUP = all(getattr(ARGS, k) == P.get_default(k) for k in (
    "material", "dt", "wall_planes", "substeps", "cover_size", "convection", "predictor",
    "newmark_gamma", "body_viscosity", "body_divergence"))
OUT = job.nest(None if ARGS.material == "saint-venant-kirchhoff" else ARGS.material,
               None if ARGS.dt is None else f"dt-{ARGS.dt:g}",
               "planes" if ARGS.wall_planes else None,
               f"substeps-{ARGS.substeps}" if ARGS.substeps else None,
               None if ARGS.cover_size is None else f"cover-{ARGS.cover_size:g}",
               "upwind3" if UPWIND3 else None,
               "predictor" if ARGS.predictor else None,
               None if ARGS.newmark_gamma is None else f"gamma-{ARGS.newmark_gamma:g}",
               None if ARGS.body_viscosity is None else f"body-viscosity-{ARGS.body_viscosity}",
               None if ARGS.body_divergence is None else f"body-divergence-{ARGS.body_divergence}")
# The substeps' CFL number: AB2 with third-order upwind fluxes is stable to about 0.58 (1D).
SUBSTEPS_CFL = 0.5 if UPWIND3 else 0.8
HERE = os.path.dirname(os.path.abspath(__file__))
GEO = os.path.join(HERE, "fold.geo")
PAPER_MODES = (1.85, 4.12, 5.45)


def scene(h, grid="paper", t_end=10.0, interval=0.05, ramp=None, fluid=True, modes=0, p_sub=None,
          upwind=None):
    """scene.toml at clearance h: the grid 100 (1 + h) across (coarse: 25 (1 + h), 140 + 10
    sponge cells along); without fluid, the solid alone (for the modes)."""
    text = open(os.path.join(HERE, "scene.toml")).read()
    text = text.replace('mesh = "fold.geo"', f'mesh = "{GEO}"')
    text = text.replace('model = "saint-venant-kirchhoff"', f'model = "{ARGS.material}"')
    if ARGS.cover_size is not None:
        text = text.replace(", side = ", f", lc_cover = {ARGS.cover_size!r}, side = ")
    text = text.replace("h = 0.02", f"h = {h!r}").replace("0.52]", f"{0.5 + h!r}]")
    nx, ny, sponge, ratio = (560, round(100 * (1 + h)), 40, 1.05) if grid == "paper" else \
        (140, round(25 * (1 + h)), 10, 1.2)
    text = text.replace("cells = [560, 102]", f"cells = [{nx}, {ny}]")
    text = text.replace("size = [5.6, 1.02]", f"size = [5.6, {1 + h!r}]")
    text = text.replace("cells = 40\n", f"cells = {sponge}\n").replace("ratio = 1.05", f"ratio = {ratio}")
    if ARGS.wall_planes:
        # A fold pressed against its own wall stays inside the channel (the model has no other
        # fold-wall contact: a free node beyond the wall stops the coupler).
        text = text.replace("[coupler]\n", f"""[[solid.plane]]
point = [0.0, 0.0]
normal = [0.0, 1.0]
bodies = ["lower"]

[[solid.plane]]
point = [0.0, {1 + h!r}]
normal = [0.0, -1.0]
bodies = ["upper"]

[coupler]
""", 1)
    if ARGS.dt is not None and fluid:
        text = text.replace("dt = 5e-5", f"dt = {ARGS.dt!r}")
    if ARGS.checkpoint_interval is not None and fluid:
        text = text.replace("[output]\n", f"[output]\ncheckpoint_interval = {ARGS.checkpoint_interval!r}\n", 1)
    if ARGS.substeps and fluid:
        text += f"\n[fluid.substeps]\nmax = {ARGS.substeps}\ncfl = {SUBSTEPS_CFL}\n"
    text = text.replace("t_end = 10.0", f"t_end = {t_end!r}").replace("interval = 0.05", f"interval = {interval!r}")
    if p_sub is not None:
        # The physical alternative at a closed glottis: the subglottal pressure is given, the
        # flux is what passes; the outlet a pressure boundary at 0 (a convective outflow fixes
        # its flux by convection alone), the sponge before it as before.
        text = text.replace('left = { type = "inflow", profile = "parabolic", mean = 1.0,',
                            f'left = {{ type = "pressure", value = {p_sub!r},')
        # The outlet's backflow (vortices leaving through the sponge) enters with total pressure
        # 0: with a static 0 it accelerated without bound at the top wall (t = 2.04 at P = 5000).
        text = text.replace('right = { type = "outflow", phase = "orlanski" }',
                            'right = { type = "pressure", value = 0.0, entering = "total" }')
    if upwind is not None:
        text = text.replace("viscosity = 6.666666666666667e-4", f"viscosity = 6.666666666666667e-4\nupwind_blend = {upwind!r}")
    if UPWIND3:
        text = text.replace("viscosity = 6.666666666666667e-4", 'viscosity = 6.666666666666667e-4\nconvection = "upwind3"')
    if ramp == "none":
        text = text.replace('ramp = "cosine", ramp_time = 0.5', 'ramp = "none"')
    if not fluid:
        lines, keep = [], True
        for line in text.splitlines():
            if line.startswith("["):
                keep = not (line.startswith("[fluid") or line.startswith("[coupler") or
                            line.startswith("[[coupler"))
            if keep:
                lines.append(line)
        text = "\n".join(lines) + "\n"
    if modes:
        text = text.replace("newton_max_iterations = 30", f"newton_max_iterations = 30\nmodes = {modes}")
    if ARGS.predictor and fluid:
        text = text.replace("newton_max_iterations = 30", 'newton_max_iterations = 30\npredictor = "acceleration"')
    if ARGS.newmark_gamma is not None:
        text = text.replace("newmark_gamma = 0.55", f"newmark_gamma = {ARGS.newmark_gamma!r}")
    if ARGS.body_viscosity is not None and fluid:
        text = text.replace("viscosity = 6.666666666666667e-4",
                            f'viscosity = 6.666666666666667e-4\nbody_viscosity = "{ARGS.body_viscosity}"')
    # The pressure inlet keeps the fluid's pressure in the compressible folds at one coupled
    # step's whatever the substeps: under "zero" each substep adds it again and, at the paper's
    # step, feeds the folds until the run stops (README.md, "What stops the pressure inlet";
    # fluid/README.md, body_divergence).
    divergence = ARGS.body_divergence or ("coupled_step" if p_sub is not None else None)
    if divergence is not None and fluid:
        text = text.replace("viscosity = 6.666666666666667e-4",
                            f'viscosity = 6.666666666666667e-4\nbody_divergence = "{divergence}"')
    return text


def one_fold(text):
    """The scene's text without the upper fold and the contact pair."""
    head, rest = text.split('[[solid.body]]\nname = "upper"', 1)
    return head + "\n"


metrics = {}
extra = {}

if ARGS.modes:
    # The solid alone (no fluid: the inertial density is rho_s = 1000, as in the paper's Eq. 28).
    two = scene(0.0, t_end=5e-5, interval=5e-5, fluid=False, modes=6)
    r1 = job.run("modes_one", one_fold(two).replace("modes = 6", "modes = 3"))
    r2 = job.run("modes_pair", two)
    f1 = outputs.summary(r1.folder)["solid"]["mode_frequencies"]
    f2 = outputs.summary(r2.folder)["solid"]["mode_frequencies"]
    x_ref, shapes = solidout.modes(r1.folder, "lower", 3)
    for k in range(3):
        metrics[f"mode{k + 1}_frequency_one_fold"] = reported(f1[k], PAPER_MODES[k])
        # The pair: Eq. 28 has no term that couples the folds (no contact at rest, no fluid),
        # so each frequency of one fold appears twice; any two combinations span the pair.
        pair = f2[2 * k:2 * k + 2]
        metrics[f"mode{k + 1}_pair_degenerate"] = at_most(
            max(abs(p - f1[k]) for p in pair) / f1[k], 1e-8)
    print("mode  one fold  pair (two frequencies)  paper")
    for k in range(3):
        print(f"{k + 1}     {f1[k]:.4f}    {f2[2 * k]:.6f} {f2[2 * k + 1]:.6f}   {PAPER_MODES[k]}")
    extra["modes"] = {"one_fold": f1, "pair": f2, "paper": PAPER_MODES}
    # Mode shapes of one fold, and the pair's mirror-symmetric (the folds move apart and together:
    # the glottis opens and closes) and antisymmetric (both move the same way) combinations.
    d = solidout.last_state(r1.folder, "lower")
    tri = d["triangles"]
    fig, ax = plt.subplots(2, 3, figsize=(13, 7))
    for k in range(3):
        phi = shapes[k][:, :2] if shapes[k].ndim == 2 else shapes[k].reshape(-1, 2)
        scale = 0.04 / np.max(np.abs(phi))
        for row, sign in ((0, 1.0), (1, -1.0)):
            a = ax[row, k]
            lower = x_ref[:, :2] + scale * phi
            upper_ref = np.column_stack([x_ref[:, 0], 1.0 - x_ref[:, 1]])
            # Mirror image of the lower fold's motion: u_x the same, u_y reversed (symmetric);
            # the antisymmetric partner reverses the mirror image.
            upper = upper_ref + sign * scale * np.column_stack([phi[:, 0], -phi[:, 1]])
            for xy, colour in ((lower, "tab:blue"), (upper, "tab:red")):
                a.triplot(xy[:, 0], xy[:, 1], tri, lw=0.25, color=colour)
            for ref in (x_ref[:, :2], upper_ref):
                a.triplot(ref[:, 0], ref[:, 1], tri, lw=0.15, color="0.8", zorder=0)
            a.set_aspect("equal")
            a.set_xlim(1.25, 2.15)
            kind = "symmetric" if row == 0 else "antisymmetric"
            a.set_title(f"mode {k + 1}, f = {f1[k]:.3f} (paper {PAPER_MODES[k]}), {kind}", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "modes.png"), dpi=120)


def coupled(name, h, grid, t_end, ramp=None, check=False, p_sub=None, upwind=None, reuse=False):
    r = job.run(name, scene(h, grid=grid, t_end=t_end, interval=0.02, ramp=ramp, p_sub=p_sub,
                            upwind=upwind),
                check=check, reuse=reuse)
    if r.cpu is not None:  # a reused run (cpu None) has no output: keep the log of its job
        with open(r.folder + ".log", "w") as f:  # the job's output, for a later look (and --sweep)
            f.write(r.log)
    err = job.first_error(r.log)
    hist = solidout.history(r.folder) if os.path.exists(os.path.join(r.folder, "solid_history.csv")) else None
    return r, err, hist


if ARGS.short:
    # h = 0: the folds touch at t = 0 and are held closed until the pressure opens them (t = 0.039
    # on this grid): contact from the first step, its release, and the open folds after. The
    # scene's cosine inflow ramp over 0.5 (README: without it the fold's downstream corner is
    # crushed on the wall at t = 0.06 on this grid).
    r, err, hist = coupled("short_h0", 0.0, "coarse", 0.15)
    ok = r.returncode == 0 and not err
    metrics["short_runs_to_the_end"] = holds(ok)
    extra["short_error"] = err
    if hist is not None:
        active = hist["active_contacts"] > 0
        t = hist["time"]
        starts = np.nonzero(active[1:] & ~active[:-1])[0] + 1
        ends = np.nonzero(~active[1:] & active[:-1])[0] + 1
        onset = float(t[starts[0]]) if len(starts) else None
        opened = float(t[ends[-1]]) if len(ends) else None
        metrics["short_contact_onset_before_0.01"] = holds(onset is not None and onset < 0.01)
        metrics["short_open_at_the_end"] = holds(len(starts) > 0 and not active[-1])
        metrics["short_contact_episodes"] = reported(float(len(starts)))
        metrics["short_penetration"] = at_most(max(0.0, -float(np.min(hist["min_gap"]))), 1e-8)
        metrics["short_newton_iterations_max"] = at_most(float(np.max(hist["newton_iterations"])), 30)
        print(f"short: end {t[-1]:.4f}, contact steps {int(active.sum())} in {len(starts)} episodes "
              f"(onset {onset}, last opening {opened}), most Newton iterations "
              f"{int(np.max(hist['newton_iterations']))}, min gap {np.min(hist['min_gap']):.3e}; {err}")
        extra["short"] = {"episode_starts": [float(t[i]) for i in starts],
                          "episode_ends": [float(t[i]) for i in ends]}


def run_name(h, grid, p_sub=None, upwind=None):
    """The name of a coupled run's scene, folder and log (--run and --sweep alike)."""
    inlet = "" if p_sub is None else f"_p{p_sub:g}"
    inlet += "" if upwind is None else f"_b{upwind:g}"
    return f"run_h{h:g}_{grid}{inlet}"


if ARGS.run is not None:
    r, err, hist = coupled(run_name(ARGS.run, ARGS.grid, ARGS.p_sub, ARGS.upwind), ARGS.run, ARGS.grid,
                           ARGS.t_end or 12.0,
                           ramp="none" if ARGS.impulsive else None, p_sub=ARGS.p_sub,
                           upwind=ARGS.upwind)
    print(f"run h = {ARGS.run}: exit {r.returncode}, {err or 'ran to the end'}, wall {r.wall:.0f} s")
    metrics[f"run_h{ARGS.run:g}_runs_to_the_end"] = holds(r.returncode == 0 and not err)
    extra["run_error"] = err

# --- The clearance sweep (paper Sec. 5.1, Figs. 12-15) ---------------------------------------
# The paper's clearances with its velocity inflow, and h = 0 with the pressure inlet (README: at
# h = 0 a given flux through a closing glottis has no solution; a given pressure has one).
SWEEP_CASES = ((0.0, None), (0.01, None), (0.02, None), (0.04, None), (0.05, None), (0.0, 5000.0))
# Spectra, amplitudes, trajectories and "contact during vibration" over t >= SETTLE: after the
# inflow ramp (0.5) and the start transient (the folds pushed to their mean position).
SETTLE = 1.0
# A run vibrates when B's u_y keeps moving: its peak-to-peak over the last third of the window is
# at least SUSTAINED times that over the first third (less: a transient dying out, whose peak is
# no vibration frequency), and above MOVES (in D: a fold at rest, round-off).
SUSTAINED, MOVES = 0.5, 1e-6
# The paper's findings on "about a tenth": a ratio of the impulses within a factor 2 of 0.1.
TENTH = (0.05, 0.2)
# A closure of the glottis: the folds touch each other: the upper fold's contact force on the
# lower one (contact_bodies) has a y component below -CLOSED. Runs written before that column
# read each fold's whole contact force, which only the other fold presses towards its wall (a
# wall plane pushes its fold away from the wall, self-contact sums to zero over a fold; either
# fold's sum may be cancelled by its plane at a time, hence both: the lower fold's below
# -CLOSED or the upper fold's above CLOSED). Active contact slots count self-contact and the
# planes too. CLOSED is in the scene's units (rho_f u_m^2 D), a thousandth of the fluid's force
# on a fold; episodes less than CLOSURE_GAP apart are one.
CLOSED, CLOSURE_GAP = 1e-3, 0.05


def folds_touch(hist):
    """Per row of solid_history.csv: whether the folds press on each other (CLOSED): from the
    upper fold's contact force on the lower one where the run wrote it (contact_bodies), else
    from each fold's whole contact force (below)."""
    if "lower.contact_bodies_fy" in hist:
        return hist["lower.contact_bodies_fy"] < -CLOSED
    return (hist["lower.contact_fy"] < -CLOSED) | (hist["upper.contact_fy"] > CLOSED)


def read_csv(path):
    """outputs.table of a run that may still be writing (the sweep also reads runs in progress),
    as {column: array}; None without the file or a data row."""
    if not os.path.exists(path):
        return None
    with warnings.catch_warnings():  # a torn last line: left out, said by numpy as a warning
        warnings.simplefilter("ignore")
        a = outputs.table(path, in_progress=True)
    return {n: a[n] for n in a.dtype.names} if a.size and a.dtype.names else None


def locked(folder):
    """Whether a job still writes into FOLDER: its first process holds an flock on FOLDER/.lock
    as long as it lives (common/runtime.cpp). Taken shared and let go at once to ask."""
    path = os.path.join(folder, ".lock")
    if not os.path.exists(path):
        return False
    with open(path) as f:
        try:
            fcntl.flock(f, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return True
        fcntl.flock(f, fcntl.LOCK_UN)
    return False


def log_error(name):
    """The first ERROR line of the run's log (written by coupled() when its job ended) and
    whether that log belongs to the job of the scene file there (written after it)."""
    scene_file, log = os.path.join(OUT, name + ".toml"), os.path.join(OUT, name + ".log")
    if not (os.path.exists(log) and os.path.exists(scene_file)
            and os.path.getmtime(log) >= os.path.getmtime(scene_file)):
        return "", False
    with open(log) as f:
        return job.first_error(f.read()), True


def run_state(name, text):
    """What is there of the run NAME of scene TEXT: "finished" (summary.json), "running" (a job
    holds the folder), "failed" (its job ended with an ERROR in the log: rerunning repeats it),
    "incomplete" (data without a summary or a log: the job was killed), "missing"."""
    scene_file, folder = os.path.join(OUT, name + ".toml"), os.path.join(OUT, name)
    if not (os.path.isdir(folder) and os.path.exists(scene_file) and open(scene_file).read() == text):
        return "missing"
    if locked(folder):
        return "running"
    if not job.same_defaults(folder):  # the same text ran under an earlier default (job.py)
        return "missing"
    if os.path.exists(os.path.join(folder, "summary.json")):
        return "finished"
    err, ended = log_error(name)
    return "failed" if ended and err else "incomplete"


def spectrum(t, x, pad=16):
    """Amplitude spectrum of x(t): resampled on a uniform grid of as many points, mean removed,
    a Hann window, zero padding to PAD times the length (next power of two); scaled by 2/sum(w),
    so that a sine of amplitude a has a peak of a. Returns (f, |X|)."""
    tu = np.linspace(t[0], t[-1], len(t))
    xu = np.interp(tu, t, x)
    w = np.hanning(len(tu))
    n = 1 << int(np.ceil(np.log2(pad * len(tu))))
    return np.fft.rfftfreq(n, tu[1] - tu[0]), np.abs(np.fft.rfft((xu - xu.mean()) * w, n)) * 2 / w.sum()


def peak(f, X, f_lo, f_hi):
    """The largest value of X over [f_lo, f_hi]: (frequency, height, at_edge). A local maximum
    is refined by a parabola through the three bins around it; at_edge: the largest value is at
    an end of the range (no peak there: a drift or a frequency outside the range)."""
    idx = np.nonzero((f >= f_lo) & (f <= f_hi))[0]
    k = int(idx[np.argmax(X[idx])])
    if k in (idx[0], idx[-1]) or not 0 < k < len(X) - 1:
        return float(f[k]), float(X[k]), True
    a, b, c = X[k - 1], X[k], X[k + 1]
    d = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c != 0 else 0.0
    return float(f[k] + d * (f[1] - f[0])), float(b - 0.25 * (a - c) * d), False


def impulse(t, fx, fy, t0=0.0):
    """Time integrals (trapezoidal) of a force's components over t >= t0."""
    m = t >= t0
    if m.sum() < 2:
        return [0.0, 0.0]
    return [float(np.trapz(fx[m], t[m])), float(np.trapz(fy[m], t[m]))]


def sweep_case(h, p_sub, grid, t_end, upwind, modes_f):
    """Take (reuse, or run) the sweep's run at clearance h (p_sub: the pressure inlet) and measure
    it; the row of the table, with the series the plots need under "data"."""
    name = run_name(h, grid, p_sub, upwind)
    text = scene(h, grid=grid, t_end=t_end, interval=0.02, p_sub=p_sub, upwind=upwind)
    folder = os.path.join(OUT, name)
    state = run_state(name, text)
    wall = None
    if state == "finished" or (state in ("missing", "incomplete") and not ARGS.no_run):
        # coupled() reuses a finished run of the identical scene (job.run checks it), else runs it.
        r, _, _ = coupled(name, h, grid, t_end, p_sub=p_sub, upwind=upwind, reuse=True)
        state = "finished" if os.path.exists(os.path.join(folder, "summary.json")) else "failed"
        wall = r.wall if r.cpu is not None else None
    # The reason a run stopped: the first ERROR line of its log (a finished run has none to give).
    err = log_error(name)[0] if state != "finished" else ""
    row = {"h": h, "inlet": "velocity" if p_sub is None else f"pressure {p_sub:g}",
           "Re": 1500 * (1 + h), "name": name, "state": state, "t_end": t_end, "error": err}
    if os.path.exists(os.path.join(folder, "summary.json")):
        s = outputs.summary(folder)
        wall = max(s["wall_time"].values()) if isinstance(s.get("wall_time"), dict) else s.get("wall_time")
        row["wall_approx"] = False
    elif state == "running":
        wall, row["wall_approx"] = time.time() - os.path.getmtime(folder + ".toml"), True
    elif wall is None and os.path.exists(folder + ".log"):
        # No summary.json from a failed job: from its scene file (written at the start) to its
        # log (written at the end).
        wall = os.path.getmtime(folder + ".log") - os.path.getmtime(folder + ".toml")
        row["wall_approx"] = True
    row["wall_s"] = wall
    probes = read_csv(os.path.join(folder, "solid_probes.csv")) if state != "missing" else None
    if probes is None:
        row.update(end=None, reached=False, measured=False)
        return row
    hist = read_csv(os.path.join(folder, "solid_history.csv"))
    forces = read_csv(os.path.join(folder, "coupler_forces.csv"))
    flow = read_csv(os.path.join(folder, "fluid_flow_rate.csv"))
    t = probes["time"]
    row["end"] = float(t[-1])
    row["reached"] = bool(state == "finished" and t[-1] >= t_end - 1e-6)
    data = {"folder": folder, "probes": probes, "hist": hist, "forces": forces}
    # Point B's vertical displacement after the start: amplitude and spectrum.
    m = t >= SETTLE
    window = float(t[m][-1] - t[m][0]) if m.sum() > 1 else 0.0
    row["window"] = [SETTLE, float(t[-1])] if m.sum() > 1 else None
    # The frequency is measured when the window holds three periods of the lowest mode.
    row["measured"] = bool(window >= 3 / modes_f[0])
    row["f_dominant"] = row["nearest_mode"] = row["f_zero_crossings"] = None
    row["amplitude_uy"] = float(np.ptp(probes["B_lower.uy"][m])) if m.any() else None
    # A spectrum needs two periods of the highest frequency looked for in the window (a run
    # that has just started has none).
    spectral = bool(m.sum() > 8 and window > 2 / (3 * modes_f[2]))
    if spectral:
        f, X = spectrum(t[m], probes["B_lower.uy"][m])
        # From two periods in the window (below: what the mean removal and window leave of a
        # drift) to three times the third eigenfrequency.
        fd, height, edge = peak(f, X, 2 / window, 3 * modes_f[2])
        k = int(np.argmin([abs(fd - fm) for fm in modes_f]))
        # A second reader: the mean period between zero crossings of u_y about its mean.
        fz = 1 / series.period(t[m], probes["B_lower.uy"][m] - np.mean(probes["B_lower.uy"][m]))
        row.update(f_dominant=fd, peak_amplitude=height, peak_at_edge=edge, nearest_mode=[k + 1, modes_f[k]],
                   f_zero_crossings=float(fz) if np.isfinite(fz) else None)
        keep = f <= 3 * modes_f[2]
        data["spectrum"] = (f[keep], X[keep])
    row["vibrates"] = False
    if spectral:
        thirds = np.array_split(probes["B_lower.uy"][m], 3)
        row["sustained_ratio"] = float(np.ptp(thirds[2]) / max(np.ptp(thirds[0]), 1e-300))
        row["vibrates"] = bool(row["amplitude_uy"] >= MOVES and row["sustained_ratio"] >= SUSTAINED
                               and not row["peak_at_edge"])
    # Contact between the folds (closures, CLOSED): the first and last time, during the
    # vibration (t >= 1), the closures (episodes); and the last time of any active slot.
    if hist is not None:
        row["contact"] = row["contact_after_settle"] = False
        row["contact_first"] = row["contact_last"] = row["any_contact_last"] = None
        row["closures"] = 0
        th = hist["time"]
        closed = folds_touch(hist)
        if closed.any():
            tc = th[closed]
            row.update(contact=True, contact_first=float(tc[0]), contact_last=float(tc[-1]),
                       contact_steps=int(closed.sum()),
                       contact_after_settle=bool((closed & (th >= SETTLE)).any()),
                       closures=int(1 + np.count_nonzero(np.diff(tc) > CLOSURE_GAP)))
        active = hist["active_contacts"] > 0
        if active.any():
            row["any_contact_last"] = float(th[active][-1])
        row["min_gap"] = float(np.min(hist["min_gap"]))
    # Forces on the lower fold and their impulses: the whole run and t >= 1. The contact force is
    # the upper fold's on it (solid_history.csv's contact_bodies columns); its whole contact force
    # adds the wall plane's reaction (and self-contact, which sums to zero), kept as
    # impulse_contact_all. A run written before those columns has the whole force only.
    if hist is not None and forces is not None:
        pair = "lower.contact_bodies_fx" in hist
        cx, cy = ("lower.contact_bodies_fx", "lower.contact_bodies_fy") if pair else \
            ("lower.contact_fx", "lower.contact_fy")
        row["impulse_contact_of"] = "the upper fold" if pair else "all contact (the wall plane's too)"
        row["impulse_contact"] = impulse(hist["time"], hist[cx], hist[cy])
        row["impulse_contact_all"] = impulse(hist["time"], hist["lower.contact_fx"], hist["lower.contact_fy"])
        row["impulse_fluid"] = impulse(forces["time"], forces["lower.fx"], forces["lower.fy"])
        row["impulse_contact_after_settle"] = impulse(hist["time"], hist[cx], hist[cy], SETTLE)
        row["impulse_fluid_after_settle"] = impulse(forces["time"], forces["lower.fx"], forces["lower.fy"],
                                                    SETTLE)
        # |contact| / |fluid| of the impulse vectors; and of the y components alone (contact
        # presses the folds together across the flow, the fluid's x force is the drag).
        jf = np.hypot(*row["impulse_fluid"])
        row["impulse_ratio"] = float(np.hypot(*row["impulse_contact"]) / jf) if jf > 0 else None
        jy = abs(row["impulse_fluid"][1])
        row["impulse_ratio_y"] = float(abs(row["impulse_contact"][1]) / jy) if jy > 0 else None
    if flow is not None and (flow["time"] >= SETTLE).any():
        row["glottal_flux_mean"] = float(np.mean(flow["Q1"][flow["time"] >= SETTLE]))
    row["data"] = data
    return row


def finding(text, rows, cases, holds_for):
    """A finding of the paper on CASES (rows of the sweep) checked on those measured (ROWS):
    "reproduced" when it holds for every one, "not reproduced" when not, "not measured" without
    any; with how many were measured and each one's numbers."""
    numbers = {f"h={r['h']:g} {r['inlet']}": holds_for(r) for r in rows}
    verdict = "not measured" if not rows else \
        "reproduced" if all(v[0] for v in numbers.values()) else "not reproduced"
    return {"finding": text, "verdict": verdict, "measured": f"{len(rows)} of {len(cases)} runs",
            "numbers": {k: v[1] for k, v in numbers.items()}}


def mode_direction(x_ref, shape, point):
    """The unit displacement of a mode at the fold's node nearest POINT."""
    phi = shape[:, :2] if shape.ndim == 2 else shape.reshape(-1, 2)
    d = phi[int(np.argmin(np.hypot(x_ref[:, 0] - point[0], x_ref[:, 1] - point[1])))]
    return d / np.hypot(*d)


def axis_angle(d):
    """The angle of a direction (degrees, modulo 180: a line has no sense)."""
    return float(np.degrees(np.arctan2(d[1], d[0])) % 180.0)


def output_gaps(folder, hist):
    """[(key, time)] of solid.h5's output steps, the gap between the folds there (the smallest
    distance between a node of one and a node of the other: solid_history.csv's min_gap counts
    the wall planes and self-contact too, 0 at every step with the planes) and whether the folds
    touch each other (CLOSED; solid_history.csv's row nearest in time)."""
    with h5py.File(os.path.join(folder, "solid.h5"), "r") as s:
        steps = [(k, float(s[k].attrs["time"])) for k in outputs.step_keys(s)]
        gaps = []
        for k, _ in steps:
            lo, up = np.array(s[k]["body_lower/position"]), np.array(s[k]["body_upper/position"])
            lo = lo[lo[:, 1] > lo[:, 1].max() - 0.1]  # the nodes near each fold's tip
            up = up[up[:, 1] < up[:, 1].min() + 0.1]
            gaps.append(float(np.sqrt(((lo[:, None, :] - up[None, :, :]) ** 2).sum(-1)).min()))
    rows = [int(np.argmin(np.abs(hist["time"] - tm))) for _, tm in steps]
    return steps, np.array(gaps), folds_touch(hist)[rows]


def draw_field(a, folder, step, time_s, title):
    """|u| near the folds (x in [1.3, 2.8]) at the output step of time TIME_S (fluid.h5, nearest
    output time) with the folds' meshes (solid.h5, step STEP)."""
    with h5py.File(os.path.join(folder, "fluid.h5"), "r") as g:
        keys = outputs.step_keys(g)
        times = np.array([float(g[k].attrs["time"]) for k in keys])
        k = keys[int(np.argmin(np.abs(times - time_s)))]
        xf, yf = np.array(g["grid/x_face"]), np.array(g["grid/y_face"])
        u, v = np.array(g[k]["u"]), np.array(g[k]["v"])
    xc = 0.5 * (xf[1:] + xf[:-1])
    cols = np.nonzero((xc >= 1.3) & (xc <= 2.8))[0]
    mag = np.hypot(u, v)[:, cols]
    pc = a.pcolormesh(xf[cols[0]:cols[-1] + 2], yf, mag, cmap="viridis", shading="flat")
    with h5py.File(os.path.join(folder, "solid.h5"), "r") as s:
        for body in ("lower", "upper"):
            xy = np.array(s[step][f"body_{body}/position"])
            a.triplot(xy[:, 0], xy[:, 1], np.array(s[f"body_{body}/triangles"]), lw=0.15, color="w")
    a.set_aspect("equal")
    a.set_xlim(1.3, 2.8)
    a.set_ylim(yf[0], yf[-1])
    a.set_title(title, fontsize=8)
    plt.colorbar(pc, ax=a, shrink=0.8, label="|u|")


def sweep_plots(rows, modes_f, x_ref, shapes):
    """spectra.png, displacement.png, frequency.png, trajectories.png, forces_h0.png, fields.png
    into OUT."""
    label = {id(r): f"h = {r['h']:g}" + ("" if r["inlet"] == "velocity" else f", {r['inlet']}") for r in rows}
    colours = plt.cm.viridis(np.linspace(0, 0.9, len(rows)))
    f_hi = 3 * modes_f[2]
    # Fig. 13: the spectra of B's u_y, each normalised by its peak, offset by clearance.
    fig, a = plt.subplots(figsize=(7, 6))
    for j, r in enumerate(rows):
        if "spectrum" in r.get("data", {}):
            f, X = r["data"]["spectrum"]
            m = f <= f_hi
            a.plot(f[m], j + X[m] / max(X[m].max(), 1e-300), color=colours[j], lw=0.9)
            note = f": peak {r['f_dominant']:.3f}" + (" (range edge)" if r["peak_at_edge"] else "") + \
                f", height {r['peak_amplitude']:.2e}" + ("" if r["measured"] else ", short window")
        else:
            note = f": no data after t = {SETTLE}"
        a.text(f_hi, j + 0.1, label[id(r)] + note, ha="right", fontsize=7)
    for k, fm in enumerate(modes_f[:3]):
        a.axvline(fm, color="k", ls=":", lw=0.8)
        a.text(fm, len(rows) + 0.05 + 0.2 * k, f"mode {k + 1}", fontsize=7, ha="center")
    a.set_xlim(0, f_hi)
    a.set_ylim(-0.1, len(rows) + 0.6)
    a.set_xlabel("frequency (u_m / D)")
    a.set_ylabel("|X| / max |X| (offset per run)")
    a.set_title(f"spectrum of B's u_y over t >= {SETTLE} (Hann window, mean removed)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "spectra.png"), dpi=120)
    plt.close(fig)
    # Fig. 13's other half: B's u_y over time, one panel per run (the spectra's window shaded).
    fig, ax = plt.subplots(len(rows), 1, figsize=(8, 1.6 * max(len(rows), 1)), squeeze=False,
                           sharex=True)
    for j, r in enumerate(rows):
        a = ax[j, 0]
        pr = r.get("data", {}).get("probes")
        if pr is not None:
            a.plot(pr["time"], pr["B_lower.uy"], color=colours[j], lw=0.5)
            if pr["time"][-1] > SETTLE:
                a.axvspan(SETTLE, pr["time"][-1], color="0.92", lw=0)
        else:
            a.text(0.5, 0.5, "no data", ha="center", transform=a.transAxes, fontsize=7)
        a.set_ylabel("u_y(B)", fontsize=7)
        a.tick_params(labelsize=7)
        a.set_title(label[id(r)], fontsize=7, loc="left")
    ax[-1, 0].set_xlabel("t (D / u_m)")
    fig.suptitle(f"point B's vertical displacement (shaded: t >= {SETTLE}, the spectra's window)",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "displacement.png"), dpi=120)
    plt.close(fig)
    # The dominant frequency against the clearance.
    fig, a = plt.subplots(figsize=(6, 4))
    for r in rows:
        if r.get("f_dominant") is not None:
            vel = r["inlet"] == "velocity"
            colour = "C0" if vel else "C3"
            a.plot(r["h"], r["f_dominant"], "o" if vel else "s", color=colour,
                   mfc=colour if r["measured"] and not r["peak_at_edge"] else "none")
            note = [r["inlet"]] if not vel else []
            note += [] if r["measured"] else ["short window"]
            note += ["range edge"] if r["peak_at_edge"] else []
            note += [] if r["vibrates"] else ["no vibration"]
            a.annotate(", ".join(note), (r["h"], r["f_dominant"]), fontsize=6, xytext=(3, 3),
                       textcoords="offset points")
    for k, fm in enumerate(modes_f[:3]):
        a.axhline(fm, color="k", ls=":", lw=0.8)
        a.text(0.055, fm, f" mode {k + 1}", fontsize=7, va="bottom")
    a.set_xlim(-0.005, 0.06)
    a.set_xlabel("clearance h / D")
    a.set_ylabel("dominant frequency of B's u_y")
    a.set_title("circles: velocity inflow, squares: pressure inlet; open: not counted", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "frequency.png"), dpi=120)
    plt.close(fig)
    # Fig. 14: the trajectories of points 1-3 about their mean, with mode 1 and 2 lines.
    points = (("B_lower", "point 1 (B)"), ("P2", "point 2"), ("P3", "point 3"))
    sel = [r for r in rows if r["inlet"] == "velocity" and r["h"] in (0.02, 0.05)]
    fig, ax = plt.subplots(max(len(sel), 1), 3, figsize=(12, 4 * max(len(sel), 1)), squeeze=False)
    for i, r in enumerate(sel):
        r["trajectories"] = {}
        pr = r.get("data", {}).get("probes")
        for j, (col, title) in enumerate(points):
            a = ax[i, j]
            a.set_title(f"h = {r['h']:g}, {title}", fontsize=8)
            if pr is None or f"{col}.ux" not in pr or not (pr["time"] >= SETTLE).any():
                why = "no data" if pr is None or f"{col}.ux" not in pr else f"no data after t = {SETTLE}"
                a.text(0.5, 0.5, why, ha="center", transform=a.transAxes)
                continue
            m = pr["time"] >= SETTLE
            ux = pr[f"{col}.ux"][m] - pr[f"{col}.ux"][m].mean()
            uy = pr[f"{col}.uy"][m] - pr[f"{col}.uy"][m].mean()
            a.plot(ux, uy, lw=0.5, color="C0")
            reach = max(np.max(np.hypot(ux, uy)), 1e-12)
            at = (pr[f"{col}.x"][0], pr[f"{col}.y"][0])
            info = {}
            for k, ls in ((0, "--"), (1, ":")):
                d = mode_direction(x_ref, shapes[k], at)
                a.plot([-reach * d[0], reach * d[0]], [-reach * d[1], reach * d[1]], "k", ls=ls, lw=0.8,
                       label=f"mode {k + 1} ({axis_angle(d):.0f} deg)")
                info[f"mode{k + 1}_angle_deg"] = axis_angle(d)
            # The trajectory's principal axis (the larger eigenvector of its covariance).
            w, vec = np.linalg.eigh(np.cov(np.vstack([ux, uy])))
            info["principal_axis_deg"] = axis_angle(vec[:, -1])
            info["extent"] = [float(np.ptp(ux)), float(np.ptp(uy))]
            r["trajectories"][title] = info
            a.set_aspect("equal", adjustable="datalim")
            a.xaxis.set_major_locator(plt.MaxNLocator(4))
            a.set_xlabel("u_x - mean")
            a.set_ylabel("u_y - mean")
            a.legend(fontsize=6, title=f"principal axis {info['principal_axis_deg']:.0f} deg", title_fontsize=6)
    if not sel:
        ax[0, 0].text(0.5, 0.5, "no run of h = 0.02 or 0.05", ha="center", transform=ax[0, 0].transAxes)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "trajectories.png"), dpi=120)
    plt.close(fig)
    # Fig. 15: contact and fluid force on the lower fold at h = 0, as far as each ran.
    zero = [r for r in rows if r["h"] == 0 and r.get("data", {}).get("forces") is not None
            and r["data"].get("hist") is not None]
    fig, ax = plt.subplots(2, max(len(zero), 1), figsize=(6 * max(len(zero), 1), 6), squeeze=False)
    for j, r in enumerate(zero):
        hs, fo = r["data"]["hist"], r["data"]["forces"]
        for i, c in enumerate(("x", "y")):
            a = ax[i, j]
            a.plot(fo["time"], fo[f"lower.f{c}"], lw=0.6, label=f"fluid, impulse {r['impulse_fluid'][i]:.4g}")
            a.plot(hs["time"], hs[f"lower.contact_f{c}"], lw=0.4, color="0.6",
                   label=f"all contact (with the wall plane), impulse {r['impulse_contact_all'][i]:.4g}")
            if f"lower.contact_bodies_f{c}" in hs:
                a.plot(hs["time"], hs[f"lower.contact_bodies_f{c}"], lw=0.6,
                       label=f"contact of the upper fold, impulse {r['impulse_contact'][i]:.4g}")
            a.set_xlabel("t")
            a.set_ylabel(f"force on the lower fold, {c}")
            a.set_title(f"{label[id(r)]}: to t = {r['end']:.3f}" + ("" if r["reached"] else f" ({r['state']})"),
                        fontsize=8)
            a.legend(fontsize=7)
    if not zero:
        ax[0, 0].text(0.5, 0.5, "no run of h = 0", ha="center", transform=ax[0, 0].transAxes)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "forces_h0.png"), dpi=120)
    plt.close(fig)
    # Fig. 12: |u| near the folds closed (smallest gap at an output step) and open (largest gap
    # after t = 1), for h = 0 (the velocity inflow when it ran to the end, the pressure inlet)
    # and for h = 0.02.
    sel = [r for r in rows if (r["h"] == 0 and (r["inlet"] != "velocity" or r["state"] == "finished"))
           or (r["h"] == 0.02 and r["inlet"] == "velocity")]
    fig, ax = plt.subplots(max(len(sel), 1), 2, figsize=(12, 3.6 * max(len(sel), 1)), squeeze=False)
    for i, r in enumerate(sel):
        r["fields"] = {}
        hist = r.get("data", {}).get("hist")
        folder = os.path.join(OUT, r["name"])
        try:
            steps, gaps, touch = output_gaps(folder, hist)
            # Closed: the smallest gap among the steps in contact after t = 1 (before, the folds
            # still touch as they started at h = 0), else among any in contact, else after t = 1;
            # open: the largest gap after t = 1. Without output after t = 1, the whole run but
            # its initial state.
            late = [n for n, (_, tm) in enumerate(steps) if tm >= SETTLE] or list(range(1, len(steps)))
            touching = list(np.nonzero(touch)[0])
            closed = [n for n in touching if n in set(late)] or touching or late
            pick = {"closed": closed[int(np.argmin(gaps[closed]))], "open": late[int(np.argmax(gaps[late]))]}
            for j, kind in enumerate(("closed", "open")):
                key, tm = steps[pick[kind]]
                where = (", contact" if touch[pick[kind]] else "") + \
                    ("" if steps[late[0]][1] >= SETTLE else f", no output after t = {SETTLE}")
                draw_field(ax[i, j], folder, key, tm, f"{label[id(r)]}, {kind}: t = {tm:.2f}, "
                           f"gap {gaps[pick[kind]]:.4f}{where}")
                r["fields"][kind] = {"time": tm, "gap": float(gaps[pick[kind]]),
                                     "contact": bool(touch[pick[kind]])}
        except (OSError, RuntimeError, KeyError, TypeError, ValueError) as e:  # no or unreadable output yet
            ax[i, 0].text(0.5, 0.5, f"{label[id(r)]}: no fields ({e})", ha="center",
                          transform=ax[i, 0].transAxes, fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "fields.png"), dpi=110)
    plt.close(fig)


if ARGS.sweep:
    t_end, upwind = ARGS.t_end or 12.0, ARGS.upwind if ARGS.upwind is not None else 0.0 if UPWIND3 else 0.2
    cases = SWEEP_CASES if ARGS.clearances is None else [(h, None) for h in ARGS.clearances]
    rows = [sweep_case(h, p, ARGS.grid, t_end, upwind, f1) for h, p in cases]
    sweep_plots(rows, f1, x_ref, shapes)
    print(f"\nsweep ({ARGS.grid} grid, t_end {t_end:g}, convection {ARGS.convection}, upwind_blend {upwind:g}); spectra over t >= {SETTLE}; "
          f"modes of one fold {', '.join(f'{v:.3f}' for v in f1)}")
    print(f"{'h/D':>5} {'inlet':<13} {'Re':>6} {'end':>7} {'f_dom':>7} {'f_0x':>7} {'mode':>10} "
          f"{'amp B.uy':>9} {'closures':>15} {'wall s':>7}  state / error")
    for r in rows:
        fd = "-" if r.get("f_dominant") is None else f"{r['f_dominant']:.3f}" + ("" if r["measured"] else "*")
        f0 = "-" if r.get("f_zero_crossings") is None else f"{r['f_zero_crossings']:.3f}"
        mode = "-" if r.get("nearest_mode") is None else f"{r['nearest_mode'][0]} ({r['nearest_mode'][1]:.3f})"
        amp = "-" if r.get("amplitude_uy") is None else f"{r['amplitude_uy']:.2e}"
        con = "-" if "contact" not in r else \
            f"{r['closures']}: {r['contact_first']:.2f}-{r['contact_last']:.2f}" if r["contact"] else "no"
        wall = "-" if r["wall_s"] is None else ("~" if r.get("wall_approx") else "") + f"{r['wall_s']:.0f}"
        end = "-" if r["end"] is None else f"{r['end']:.3f}"
        print(f"{r['h']:>5g} {r['inlet']:<13} {r['Re']:>6.0f} {end:>7} {fd:>7} {f0:>7} {mode:>10} {amp:>9} "
              f"{con:>15} {wall:>7}  {r['state']}{': ' + r['error'] if r['error'] else ''}")
    print("(* the window after t = 1 holds fewer than three periods of mode 1: not counted; ~ wall time "
          "from the files' times)")
    for r in rows:
        if r["h"] == 0 and "impulse_fluid" in r:
            jf, jc = r["impulse_fluid"], r["impulse_contact"]
            ratio = "-" if r["impulse_ratio"] is None else f"{r['impulse_ratio']:.4g}"
            ratio_y = "-" if r["impulse_ratio_y"] is None else f"{r['impulse_ratio_y']:.4g}"
            ja = r["impulse_contact_all"]
            print(f"h = 0, {r['inlet']}: impulses on the lower fold to t = {r['end']:.3f}: fluid "
                  f"({jf[0]:.5g}, {jf[1]:.5g}), contact of {r['impulse_contact_of']} ({jc[0]:.5g}, "
                  f"{jc[1]:.5g}), |contact| / |fluid| = {ratio} (y alone {ratio_y}); all contact "
                  f"({ja[0]:.5g}, {ja[1]:.5g})")
        key = f"sweep_{r['name']}"
        metrics[f"{key}_runs_to_the_end"] = holds(r["reached"])
        if r["end"] is not None:
            metrics[f"{key}_end_time"] = reported(r["end"], t_end)
        if r.get("f_dominant") is not None:
            metrics[f"{key}_dominant_frequency"] = reported(r["f_dominant"], r["nearest_mode"][1])
        if r.get("amplitude_uy") is not None:
            metrics[f"{key}_uy_amplitude"] = reported(r["amplitude_uy"])
        if "contact" in r:
            metrics[f"{key}_contact"] = reported(float(r["contact"]))
            metrics[f"{key}_closures"] = reported(float(r["closures"]))
        if r.get("impulse_ratio") is not None and r["h"] == 0:
            metrics[f"{key}_contact_over_fluid_impulse"] = reported(r["impulse_ratio"], 0.1)
    # The paper's findings, on the runs whose window after t = 1 holds three periods of mode 1.
    every = [r for r in rows if r["inlet"] == "velocity"]
    vel = [r for r in every if r["measured"]]

    def near_mode(k):
        return lambda r: (r["vibrates"] and r["nearest_mode"][0] == k,
                          {"f_dominant": r["f_dominant"], "nearest_mode": r["nearest_mode"][0],
                           "amplitude_uy": r["amplitude_uy"], "vibrates": r["vibrates"],
                           "sustained_ratio": r["sustained_ratio"], "peak_at_edge": r["peak_at_edge"]})

    def contact(r):
        return (r["contact_after_settle"] == (r["h"] <= 0.01),
                {"contact_after_t_settle": r["contact_after_settle"], "contact_first": r["contact_first"],
                 "contact_last": r["contact_last"], "closures": r["closures"]})

    findings = [
        finding("small clearances (h <= 0.02) vibrate near mode 2", [r for r in vel if r["h"] <= 0.02],
                [r for r in every if r["h"] <= 0.02], near_mode(2)),
        finding("large clearances (h >= 0.04) vibrate near mode 1", [r for r in vel if r["h"] >= 0.04],
                [r for r in every if r["h"] >= 0.04], near_mode(1)),
        finding(f"contact (after t = {SETTLE}) only for h <= 0.01", [r for r in vel if "contact" in r],
                every, contact),
        finding(f"at h = 0 the contact impulse is about a tenth of the fluid impulse (ratio within "
                f"{TENTH[0]}-{TENTH[1]})",
                [r for r in rows if r["h"] == 0 and r.get("impulse_ratio") is not None],
                [r for r in rows if r["h"] == 0],
                lambda r: (TENTH[0] <= r["impulse_ratio"] <= TENTH[1],
                           {"ratio": r["impulse_ratio"], "ratio_y": r["impulse_ratio_y"], "to_t": r["end"]})),
    ]
    # "contact only for h <= 0.01" needs both sides of the clearance measured.
    if not ({r["h"] <= 0.01 for r in vel if "contact" in r} >= {True, False}) \
            and findings[2]["verdict"] != "not reproduced":
        findings[2]["verdict"] = "not measured"
    print("the paper's findings (frequencies from runs with three periods of mode 1 after t = "
          f"{SETTLE}; vibrating: B's u_y keeps >= {SUSTAINED} of its first third's range in the last):")
    for fnd in findings:
        print(f"  {fnd['finding']}: {fnd['verdict']} ({fnd['measured']} measured) {json.dumps(fnd['numbers'])}")
    extra["sweep"] = [{k: v for k, v in r.items() if k != "data"} for r in rows]
    extra["sweep_findings"] = findings
    extra["sweep_settings"] = {"grid": ARGS.grid, "t_end": t_end, "upwind_blend": upwind,
                               "convection": ARGS.convection, "settle": SETTLE,
                               "sustained": SUSTAINED, "moves": MOVES, "modes_one_fold": f1}

extra["material"] = ARGS.material
finish("vocal-folds", metrics, extra, short=ARGS.short and not ARGS.modes,
       copies=[os.path.join(TOP, "summary.json")] if DEFAULT_SETUP and OUT != TOP else [])
