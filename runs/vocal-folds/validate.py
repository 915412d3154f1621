#!/usr/bin/python3
"""Vocal folds (paper Sec. 5.1): two mirrored two-layer M5 folds in a channel, frictionless
contact between them.

--modes: the first three eigenfrequencies and mode shapes of one fold (paper Eq. 28; the paper
  finds 1.85, 4.12, 5.45 for its geometry) and of the pair, the pair's modes as mirror-symmetric
  and antisymmetric combinations; modes.png.
--short: h = 0 (the folds touch at t = 0) on a coarse grid through the first contact episodes;
  fails when contact in the flow breaks (Newton, penetration) or the run stops.
--run H: one coupled run at clearance h/D = H (--grid paper|coarse, --t-end T, --impulsive:
  no inflow ramp).
With no option: --modes and --short."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import job  # noqa: E402
import outputs  # noqa: E402
import solidout  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import at_most, finish, holds, reported  # noqa: E402

P = cli.parser(__doc__)
P.add_argument("--modes", action="store_true", help="eigenmodes of one fold and of the pair")
P.add_argument("--run", type=float, metavar="H", help="one coupled run at clearance h/D = H")
P.add_argument("--grid", choices=("paper", "coarse"), default="paper", help="grid of --run")
P.add_argument("--t-end", type=cli.positive, default=10.0, help="end time of --run")
P.add_argument("--impulsive", action="store_true", help="--run without the inflow ramp")
P.add_argument("--upwind", type=float, metavar="B", default=None,
               help="--run with fluid.upwind_blend = B (first-order upwind weight outside the sponge)")
P.add_argument("--p-sub", type=float, metavar="P", default=None,
               help="--run with a pressure inlet: subglottal pressure P (ramped like the inflow), "
                    "pressure 0 at the outlet, instead of the velocity inflow")
ARGS = P.parse_args()
if not (ARGS.modes or ARGS.short or ARGS.run is not None):
    ARGS.modes = ARGS.short = True
OUT = job.out_dir("vocal-folds")
HERE = os.path.dirname(os.path.abspath(__file__))
GEO = os.path.join(HERE, "fold.geo")
PAPER_MODES = (1.85, 4.12, 5.45)


def scene(h, grid="paper", t_end=10.0, interval=0.05, ramp=None, fluid=True, modes=0, p_sub=None,
          upwind=None):
    """scene.toml at clearance h: the grid 100 (1 + h) across (coarse: 25 (1 + h), 140 + 10
    sponge cells along); without fluid, the solid alone (for the modes)."""
    text = open(os.path.join(HERE, "scene.toml")).read()
    text = text.replace('mesh = "fold.geo"', f'mesh = "{GEO}"')
    text = text.replace("h = 0.02", f"h = {h!r}").replace("0.52]", f"{0.5 + h!r}]")
    nx, ny, sponge, ratio = (560, round(100 * (1 + h)), 40, 1.05) if grid == "paper" else \
        (140, round(25 * (1 + h)), 10, 1.2)
    text = text.replace("cells = [560, 102]", f"cells = [{nx}, {ny}]")
    text = text.replace("size = [5.6, 1.02]", f"size = [5.6, {1 + h!r}]")
    text = text.replace("cells = 40\n", f"cells = {sponge}\n").replace("ratio = 1.05", f"ratio = {ratio}")
    text = text.replace("t_end = 10.0", f"t_end = {t_end!r}").replace("interval = 0.05", f"interval = {interval!r}")
    if p_sub is not None:
        # The physical alternative at a closed glottis: the subglottal pressure is given, the
        # flux is what passes; the outlet a pressure boundary at 0 (a convective outflow fixes
        # its flux by convection alone), the sponge before it as before.
        text = text.replace('left = { type = "inflow", profile = "parabolic", mean = 1.0,',
                            f'left = {{ type = "pressure", value = {p_sub!r},')
        text = text.replace('right = { type = "outflow", phase = "orlanski" }',
                            'right = { type = "pressure", value = 0.0 }')
    if upwind is not None:
        text = text.replace("viscosity = 6.666666666666667e-4", f"viscosity = 6.666666666666667e-4\nupwind_blend = {upwind!r}")
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


def coupled(name, h, grid, t_end, ramp=None, check=False, p_sub=None, upwind=None):
    r = job.run(name, scene(h, grid=grid, t_end=t_end, interval=0.02, ramp=ramp, p_sub=p_sub,
                            upwind=upwind),
                check=check)
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

if ARGS.run is not None:
    inlet = "" if ARGS.p_sub is None else f"_p{ARGS.p_sub:g}"
    inlet += "" if ARGS.upwind is None else f"_b{ARGS.upwind:g}"
    r, err, hist = coupled(f"run_h{ARGS.run:g}_{ARGS.grid}{inlet}", ARGS.run, ARGS.grid, ARGS.t_end,
                           ramp="none" if ARGS.impulsive else None, p_sub=ARGS.p_sub,
                           upwind=ARGS.upwind)
    print(f"run h = {ARGS.run}: exit {r.returncode}, {err or 'ran to the end'}, wall {r.wall:.0f} s")
    metrics[f"run_h{ARGS.run:g}_runs_to_the_end"] = holds(r.returncode == 0 and not err)
    extra["run_error"] = err

finish("vocal-folds", metrics, extra, short=ARGS.short and not ARGS.modes)
