#!/usr/bin/python3
"""The glycocalyx channel (paper Sec. 5.2, Table 4): a pulsatile flow over a wavy wall, rigid or
elastic, with or without sixteen fibers clamped on it (make_scene.py writes the scenes;
README.md states the set-up and what was chosen where the paper's text is silent).

Four variants (rigid / elastic wall, without / with fibers), each for --periods periods of the
driving (T = 1.2); statistics over the last --last periods:
- at point C on the wall (the trough x = 1/2): the wall shear stress tau (paper Eq. 30; mean and
  amplitude (max - min)/2) and the pressure's amplitude, from [[coupler.surface_probe]];
- the flow rate through x = 1/2 (amplitude and mean);
- the fluid velocity at D (centre line above C) and the wall's velocity at C: their amplitudes
  and their phases at the driving frequency, against that of the flow rate (whose own phase is
  given against the driving force);
and the paper's findings as reported (not judged) yes/no: fibers lower the WSS at C, the elastic
wall lowers it further, fibers raise the pressure fluctuation at C, fibers lower the flow-rate
fluctuation, the wall moves in phase with the pulsation. --sweep adds the elastic wall with
fibers at other Young's moduli (the flow-rate amplitude against E, the paper's Fig. 23).

Outputs in OUT (FSI_OUT, else out/glycocalyx): the runs in runs/<variant>/, summary.json (the
metrics; the numbers behind the figures under profiles, fields, flow_rate_vs_E) and the figures
(figures.py draws all but the first):
- glycocalyx.png: p and tau at C, the flow rate, u at D and the wall's velocity at C over the
  last periods (the paper's Figs. 19, 20, 22);
- profiles.png: u(y) along x = 1/2 from the wall's surface at C to y = 3H/4, the variants on one
  axes, at the output time of the last period where the driving |sin(2 pi t / T)| is smallest
  (t = kT/2; of equal ones the latest; Fig. 21);
- fields_<variant>.png, for the variants with fibers: the pressure with velocity vectors, the
  fibers and the wall at the output times of the last period with the largest forward and the
  largest backward flow rate (Figs. 17-18);
- flow_rate_vs_E.png, with --sweep: the flow-rate amplitude against E, with the default E's
  elastic wall with fibers and the rigid wall with fibers (E -> infinity) when they ran (Fig. 23).
"The last period" of a figure is that of the output steps written (every 0.1), so a short test
run draws its last steps.

--short (./fsi test): the elastic wall with fibers for 400 steps; judged: the run holds (the
fibers' root inertia on a wall whose nodes are 60 times lighter than a fiber: explicit, it
diverges within 10 steps), and the wall at C moves slower than the fluid at D.
Environment: FSI_BIN, FSI_OUT, FSI_ROOT; FSI_MPIRUN (default mpirun)."""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "lib"))
sys.path.insert(0, HERE)
import cli  # noqa: E402
import figures  # noqa: E402
import job  # noqa: E402
import make_scene  # noqa: E402
import numpy as np  # noqa: E402
from metrics import at_most, finish, holds, reported  # noqa: E402
from outputs import table  # noqa: E402

P = cli.parser(__doc__)
P.add_argument("--periods", type=cli.positive, default=10.0, help="periods per variant (10)")
P.add_argument("--last", type=cli.positive, default=2.0,
               help="periods at the end the statistics cover (2)")
P.add_argument("--variants", default="rigid,rigid-fibers,elastic-fibers,elastic",
               help="comma-separated, of rigid, rigid-fibers, elastic-fibers, elastic")
P.add_argument("--sweep", type=lambda t: [float(v) for v in t.split(",")], default=None,
               help="Young's moduli of the wall for the elastic wall with fibers, e.g. 3,30,100")
P.add_argument("--reuse", action="store_true", help="keep finished runs of identical scenes")
ARGS = P.parse_args()
OUT = job.out_dir("glycocalyx")
T = make_scene.PERIOD
OMEGA = 2 * math.pi / T

VARIANTS = {"rigid": (False, False), "rigid-fibers": (False, True),
            "elastic-fibers": (True, True), "elastic": (True, False)}


def run(name, elastic, fibers, periods, e_wall=make_scene.E_WALL, interval=0.1):
    text = make_scene.scene(name, elastic=elastic, fibers=fibers, periods=periods, e_wall=e_wall,
                            interval=interval)
    return job.run(name, text, work=os.path.join(OUT, "runs"), reuse=ARGS.reuse)


def window(t, t_end, last):
    return t >= t_end - last * T - 1e-9


def amplitude(y):
    return 0.5 * (float(np.max(y)) - float(np.min(y)))


def phase(t, y):
    """The phase (radians) of y's component at the driving frequency over whole periods."""
    c = np.trapz(y * np.exp(-1j * OMEGA * t), t)
    return float(np.angle(c))


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def statistics(folder, elastic, t_end, last):
    s = table(os.path.join(folder, "coupler_surface.csv"))
    q = table(os.path.join(folder, "fluid_flow_rate.csv"))
    d = table(os.path.join(folder, "fluid_probes.csv"))
    ws, wq, wd = (window(x["time"], t_end, last) for x in (s, q, d))
    out = {"tau_mean": float(np.mean(s["C.tau"][ws])), "tau_amplitude": amplitude(s["C.tau"][ws]),
           "p_amplitude": amplitude(s["C.p"][ws]),
           "flow_rate_mean": float(np.mean(q["Q0"][wq])), "flow_rate_amplitude": amplitude(q["Q0"][wq]),
           "u_D_amplitude": amplitude(d["D.ux"][wd])}
    phi_q = phase(q["time"][wq], q["Q0"][wq])
    # against the driving sin(wt), whose phase by phase() is -pi/2
    out["flow_rate_phase_deg"] = math.degrees(wrap(phi_q + math.pi / 2))
    out["u_D_phase_deg"] = math.degrees(wrap(phase(d["time"][wd], d["D.ux"][wd]) - phi_q))
    if elastic:
        c = table(os.path.join(folder, "solid_probes.csv"))
        wc = window(c["time"], t_end, last)
        out["wall_v_C_amplitude"] = amplitude(c["C.vx"][wc])
        out["wall_v_C_phase_deg"] = math.degrees(wrap(phase(c["time"][wc], c["C.vx"][wc]) - phi_q))
    return out


def plots(folders, t_end, last):
    """Figs. 19, 20, 22 of the paper: p and tau at C, u at D and the wall's velocity at C, the
    flow rate, over the last periods of each variant (glycocalyx.png)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for v, (folder, elastic) in folders.items():
        s = table(os.path.join(folder, "coupler_surface.csv"))
        q = table(os.path.join(folder, "fluid_flow_rate.csv"))
        d = table(os.path.join(folder, "fluid_probes.csv"))
        w = window(s["time"], t_end, last)
        ax[0, 0].plot(s["time"][w], s["C.p"][w] - np.mean(s["C.p"][w]), label=v)
        ax[0, 1].plot(s["time"][w], s["C.tau"][w], label=v)
        wq = window(q["time"], t_end, last)
        ax[1, 0].plot(q["time"][wq], q["Q0"][wq], label=v)
        wd = window(d["time"], t_end, last)
        line, = ax[1, 1].plot(d["time"][wd], d["D.ux"][wd], label=f"{v}: u at D")
        if elastic:
            c = table(os.path.join(folder, "solid_probes.csv"))
            wc = window(c["time"], t_end, last)
            ax[1, 1].plot(c["time"][wc], 10 * c["C.vx"][wc], "--", color=line.get_color(),
                          label=f"{v}: 10 x wall v_x at C")
    for a, title in zip(ax.flat, ["pressure at C (minus its mean)", "wall shear stress at C",
                                  "flow rate through x = 1/2", "velocity at D, wall at C"]):
        a.set_title(title)
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    for a in ax[1]:
        a.set_xlabel("t")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "glycocalyx.png"), dpi=110)
    plt.close(fig)


def short():
    steps = 400
    r = job.run("short", make_scene.scene("glycocalyx-short", periods=steps * make_scene.DT / T,
                                          interval=0.01),
                work=os.path.join(OUT, "runs"), check=False)
    metrics = {"run_holds": holds(r.returncode == 0)}
    if r.returncode != 0:
        print(job.first_error(r.log))
    else:
        c = table(os.path.join(r.folder, "solid_probes.csv"))
        d = table(os.path.join(r.folder, "fluid_probes.csv"))
        wall = float(np.max(np.hypot(c["C.vx"], c["C.vy"])))
        fluid = float(np.max(np.abs(d["D.ux"])))
        print(f"glycocalyx --short: {steps} steps in {r.wall:.1f} s; wall speed at C up to "
              f"{wall:.3e}, fluid speed at D up to {fluid:.3e}")
        metrics["wall_speed_C_over_fluid_speed_D"] = at_most(wall / fluid, 1.0)
    finish("glycocalyx", metrics, short=True)


def main():
    if ARGS.short:
        return short()
    periods, last = ARGS.periods, min(ARGS.last, ARGS.periods)
    t_end = periods * T
    results, metrics, folders = {}, {}, {}
    for v in ARGS.variants.split(","):
        if v not in VARIANTS:
            raise SystemExit(f"--variants: unknown variant '{v}' (of {', '.join(VARIANTS)})")
        elastic, fibers = VARIANTS[v]
        r = run(f"{v}", elastic, fibers, periods)
        results[v] = statistics(r.folder, elastic, t_end, last)
        results[v]["wall_s"] = r.wall
        folders[v] = (r.folder, elastic)
        print(f"{v}: " + ", ".join(f"{k} {x:.4g}" for k, x in results[v].items()), flush=True)
        for k, x in results[v].items():
            metrics[f"{v}.{k}"] = reported(x)
    r = results
    findings = []
    for wall in ("rigid", "elastic"):
        bare, fib = r.get(wall), r.get(f"{wall}-fibers")
        if not (bare and fib):
            continue
        findings += [(f"fibers_lower_wss_amplitude_at_C_{wall}",
                      fib["tau_amplitude"] < bare["tau_amplitude"]),
                     (f"fibers_raise_pressure_fluctuation_at_C_{wall}",
                      fib["p_amplitude"] > bare["p_amplitude"]),
                     (f"fibers_lower_flow_rate_fluctuation_{wall}",
                      fib["flow_rate_amplitude"] < bare["flow_rate_amplitude"])]
    if "rigid-fibers" in r and "elastic-fibers" in r:
        findings.append(("elastic_wall_lowers_wss_amplitude_further",
                         r["elastic-fibers"]["tau_amplitude"] < r["rigid-fibers"]["tau_amplitude"]))
    for v in ("elastic", "elastic-fibers"):
        if v in r:
            findings.append((f"wall_moves_in_phase_with_flow_{v}",
                             abs(r[v]["wall_v_C_phase_deg"]) < 30.0))
    for k, ok in findings:
        metrics[k] = reported(float(ok))
        print(f"  {k}: {'yes' if ok else 'no'}")
    sweep = {}
    for e in ARGS.sweep or []:
        name = f"elastic-fibers-E{e:g}"
        rr = run(name, True, True, periods, e_wall=e)
        sweep[e] = statistics(rr.folder, True, t_end, last)
        sweep[e]["wall_s"] = rr.wall
        metrics[f"sweep_E{e:g}.flow_rate_amplitude"] = reported(sweep[e]["flow_rate_amplitude"])
        print(f"E = {e:g}: flow-rate amplitude {sweep[e]['flow_rate_amplitude']:.5g}", flush=True)
    plots(folders, t_end, last)
    # The paper's Figs. 21, 17-18 and 23 from the run folders (figures.py): reported, not judged.
    paths = {v: f for v, (f, _) in folders.items()}
    drawn = {"profiles": figures.profiles(paths, os.path.join(OUT, "profiles.png"))}
    ts = ", ".join(f"{v} {x['t']:.4g}" for v, x in drawn["profiles"].items())
    print(f"profiles.png: u(y) through C at the smallest driving, t = ({ts})")
    drawn["fields"] = {}
    for v, folder in paths.items():
        if VARIANTS[v][1]:
            drawn["fields"][v] = figures.fields(folder, v, os.path.join(OUT, f"fields_{v}.png"))
            print(f"fields_{v}.png: " + ", ".join(
                f"t = {x['t']:.4g} (largest {k} flow: Q = {x['flow_rate']:.3g})"
                for k, x in drawn["fields"][v].items()))
    if sweep:
        # the default E's run is the variant elastic-fibers (when it ran), E -> infinity the
        # rigid wall with fibers
        amplitudes = {e: x["flow_rate_amplitude"] for e, x in sweep.items()}
        if "elastic-fibers" in r:
            amplitudes.setdefault(make_scene.E_WALL, r["elastic-fibers"]["flow_rate_amplitude"])
        rigid = r["rigid-fibers"]["flow_rate_amplitude"] if "rigid-fibers" in r else None
        drawn["flow_rate_vs_E"] = figures.flow_rate_vs_e(amplitudes, rigid, make_scene.E_WALL,
                                                         os.path.join(OUT, "flow_rate_vs_E.png"))
        print("flow_rate_vs_E.png: " + ", ".join(f"E = {e:g}: {a:.4g}" for e, a in sorted(
            amplitudes.items())) + ("" if rigid is None else f", rigid: {rigid:.4g}"))
    print("\n| variant | tau mean at C | tau amplitude | p amplitude at C | flow-rate amplitude | "
          "wall v at C, phase | wall s |")
    print("|---|---|---|---|---|---|---|")
    for v, x in r.items():
        wall = (f"{x['wall_v_C_amplitude']:.3g}, {x['wall_v_C_phase_deg']:.0f}°"
                if "wall_v_C_amplitude" in x else "-")
        print(f"| {v} | {x['tau_mean']:.4g} | {x['tau_amplitude']:.4g} | {x['p_amplitude']:.4g} | "
              f"{x['flow_rate_amplitude']:.4g} | {wall} | {x['wall_s']:.0f} |")
    finish("glycocalyx", metrics, {"variants": r, "sweep": {str(k): v for k, v in sweep.items()},
                                   "periods": periods, "last": last, **drawn})


if __name__ == "__main__":
    main()
