#!/usr/bin/python3
"""Contact: (1) two elastic blocks pressed together, frictionless node-to-segment contact both
ways with Lagrange multipliers, non-matching meshes: no penetration beyond 1e-8 of the block
size, contact force equal to the applied load (the support reaction at the pushed top) within
1e-8, action = reaction between the blocks. (2) A block dropped on a rigid plane: no
penetration, no energy growth (contact steps dissipate, paper Eq. 13-14), it bounces."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import cli  # noqa: E402
import job  # noqa: E402
import outputs  # noqa: E402
import scenes  # noqa: E402
import solidout  # noqa: E402
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from metrics import finish, metric  # noqa: E402

ARGS = cli.parser(__doc__).parse_args()
OUT = job.out_dir("contact-blocks")

HERE = os.path.dirname(os.path.abspath(__file__))
metrics = {}
fig, ax = plt.subplots(1, 3, figsize=(14, 4))

# (1) Two blocks.
folder, wall_blocks, *_ = job.run("blocks", scenes.edit(os.path.join(HERE, "blocks.toml"), {}))
s = outputs.summary(folder)["solid"]
base, punch = s["bodies"]
load = punch["reactions"]["top"][1]           # what pushes the punch down (negative)
fc_punch, fc_base = punch["contact_force"][1], base["contact_force"][1]
support = base["reactions"]["bottom"][1]
size = 0.5
penetration = max(0.0, -s["min_contact_gap"]) / size
metrics["blocks_penetration"] = metric(penetration, 0.0, penetration, 1e-8)
metrics["blocks_contact_force_vs_load"] = metric(fc_punch, -load, abs(fc_punch + load) / abs(load), 1e-8)
metrics["blocks_action_reaction"] = metric(fc_base, -fc_punch, abs(fc_base + fc_punch) / abs(fc_punch), 1e-8)
metrics["blocks_support_vs_load"] = metric(support, -load, abs(support + load) / abs(load), 1e-8)
print(f"blocks: load {load:.10g}, contact force on punch {fc_punch:.10g}, on base {fc_base:.10g}, "
      f"min gap {s['min_contact_gap']:.3e}, Newton {s['newton_iterations']} over {s['steps']} load steps")
for name, colour in (("base", "tab:blue"), ("punch", "tab:red")):
    d = solidout.last_state(folder, name)
    x = d["position"]
    ax[0].triplot(x[:, 0], x[:, 1], d["triangles"], lw=0.3, color=colour)
    if name == "base":
        top = np.abs(d["x_ref"][:, 1] - 0.5) < 1e-12
        order = np.argsort(d["x_ref"][top, 0])
        ax[1].plot(d["x_ref"][top, 0][order], d["contact_pressure"][top][order], "o-", ms=3, label="base (nodes)")
    else:
        bottom = np.abs(d["x_ref"][:, 1] - 0.5) < 1e-12
        order = np.argsort(d["x_ref"][bottom, 0])
        ax[1].plot(d["x_ref"][bottom, 0][order], d["contact_pressure"][bottom][order], "s-", ms=3, label="punch (nodes)")
ax[0].set_aspect("equal")
ax[0].set_title("pressed blocks (deformed)")
ax[1].set_xlabel("x")
ax[1].set_ylabel("contact pressure (node force / length)")
ax[1].legend(fontsize=7)

# (2) Drop on a rigid plane.
replace = {"t_end": "t_end = 0.15"} if ARGS.short else {}
folder, wall_drop, *_ = job.run("drop", scenes.edit(os.path.join(HERE, "drop.toml"), replace))
h = solidout.history(folder)
p = solidout.probes(folder)
mgh = 10 * 0.4 * 0.2 * 10 * 0.05     # rho A g h: the energy of the drop
e = h["total_energy"]
growth = float(np.max(e - e[0])) / mgh
gap = float(np.min(h["min_gap"]))
active = h["active_contacts"] > 0
first = int(np.argmax(active))
v_impact = -float(np.min(p["centre.vy"][:first + 1]))
starts = np.nonzero(active[1:] & ~active[:-1])[0] + 1
ends = np.nonzero(~active[1:] & active[:-1])[0] + 1
episodes = [float((e[t] - e[s0 - 1]) / mgh) for s0, t in zip(starts, ends)]
metrics["drop_penetration"] = metric(max(0.0, -gap) / 0.4, 0.0, max(0.0, -gap) / 0.4, 1e-8)
metrics["drop_energy_growth"] = metric(growth, 0.0, max(growth, 0.0), 1e-9)
# Rebound: the centre's highest point after the first contact ends, above its height at impact,
# against the drop height 0.05.
release = int(ends[0]) if len(ends) else len(active) - 1
rebound = float(np.max(p["centre.y"][release:]) - p["centre.y"][first]) / 0.05
metrics["drop_bounces"] = metric(rebound, 1.0, 0.0 if rebound > 0 and len(ends) else 1.0, 0.5)
print(f"drop: impact speed {v_impact:.4f}, rebound {rebound:.3f} of the drop height, energy growth "
      f"{growth:.2e} m g h, energy change over each contact episode {['%.2e' % x for x in episodes]} m g h, "
      f"min gap {gap:.2e}")
ax[2].plot(h["time"], e / mgh, label="total energy / m g h")
ax[2].plot(h["time"], h["kinetic"] / mgh, lw=0.6, label="kinetic")
ax[2].plot(h["time"], h["strain"] / mgh, lw=0.6, label="strain")
ax[2].plot(p["time"], (p["centre.y"] - 0.1) / 0.05, "k--", lw=0.8, label="height of the base / drop")
ax[2].set_xlabel("t")
ax[2].legend(fontsize=7)
ax[2].set_title("block dropped on a rigid plane")
fig.tight_layout()
fig.savefig(os.path.join(OUT, "contact.png"), dpi=120)
finish("contact-blocks", metrics, {"blocks": {"load": load, "contact_force_punch": fc_punch,
                                                 "contact_force_base": fc_base, "wall_s": wall_blocks},
                                      "drop": {"impact_speed": v_impact, "rebound_height_ratio": rebound,
                                               "episodes_energy_change": episodes, "wall_s": wall_drop}}, short=ARGS.short)
