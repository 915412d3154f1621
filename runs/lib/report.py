"""Speed against error on one page: what `./fsi validate` wrote (each case's summary.json: its
metrics, the jobs' wall and CPU time, per-run entries of metrics.run_entry), the benchmarks'
JSON (`./fsi bench`) and the peers' measured and published numbers (peers.csv beside this file)
gathered into an HTML page with PNG plots. runs/report.py is its command line."""
import datetime
import glob
import html
import json
import os
import shutil
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import outputs  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
BENCHES = ["fluid", "solid", "fiber", "coupler", "coupled", "protocol"]


def peers(path=os.path.join(HERE, "peers.csv")):
    """Rows of peers.csv as dicts (numbers as float, empty as None)."""
    rows = outputs.commented_rows(path)
    for r in rows:
        for k in ("value", "error", "cpu_s"):
            r[k] = float(r[k]) if r.get(k) else None
    return rows


def cases(out):
    """Every case summary under out/ (a summary.json with "case" and "metrics"), by case name."""
    found = {}
    for path in sorted(glob.glob(os.path.join(out, "*", "summary.json"))):
        try:
            with open(path) as f:
                s = json.load(f)
        except (OSError, ValueError) as e:
            found[os.path.basename(os.path.dirname(path))] = {"unreadable": str(e), "path": path}
            continue
        if isinstance(s, dict) and "case" in s and "metrics" in s:
            s["path"] = path
            s["written"] = datetime.datetime.fromtimestamp(os.path.getmtime(path)).strftime(
                "%Y-%m-%d %H:%M")
            found[s["case"]] = s
    return found


def machine():
    """Cores, CPU model, memory, date and the git commit of the tree."""
    model, mem, load = "unknown", "unknown", "unknown"
    try:
        for ln in open("/proc/cpuinfo"):
            if ln.startswith("model name"):
                model = ln.split(":", 1)[1].strip()
                break
        for ln in open("/proc/meminfo"):
            if ln.startswith("MemTotal"):
                mem = f"{int(ln.split()[1]) / 2 ** 20:.1f} GiB"
                break
        load = open("/proc/loadavg").read().split()[0]
    except OSError:
        pass
    root = os.path.abspath(os.path.join(HERE, "..", ".."))

    def git(*a):
        r = subprocess.run(["git", "-C", root, *a], capture_output=True, text=True)
        return r.stdout.strip() if r.returncode == 0 else ""
    commit = git("rev-parse", "HEAD") or "unknown (not a git checkout)"
    if git("status", "--porcelain", "--untracked-files=no"):
        commit += " (with uncommitted changes)"
    return {"cores": os.cpu_count(), "cpu": model, "memory": mem, "load": load, "commit": commit,
            "date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M")}


def _fmt(x, spec=".4g"):
    if x is None:
        return "–"
    if isinstance(x, bool):
        return str(x)
    if isinstance(x, (int, float)):
        return format(x, spec)
    return html.escape(str(x))


def _time_axis(entries):
    """'cpu_s' when every entry has a CPU time, else 'wall_s'."""
    return "cpu_s" if all(e.get("cpu_s") for e in entries) else "wall_s"


def case_plot(name, s, peer_rows, dest):
    """Error against CPU time (wall where CPU is missing) of each per-run entry, one series per
    quantity, the peers' points of the case beside; the PNG's file name, else None."""
    runs = [e for e in s.get("per_run", []) if e.get("error") is not None]
    timed_peers = [p for p in peer_rows if p["cpu_s"] and p["error"] is not None]
    if not runs and not timed_peers:
        return None
    fig, ax = plt.subplots(figsize=(6.4, 4.4), layout="constrained")
    key = _time_axis(runs) if runs else "cpu_s"
    quantities = list(dict.fromkeys(e["quantity"] for e in runs))
    for k, q in enumerate(quantities):
        e = [r for r in runs if r["quantity"] == q and r.get(key)]
        if not e:
            continue
        t = [r[key] for r in e]
        err = [max(abs(r["error"]), 1e-16) for r in e]
        ax.loglog(t, err, "o-", color=f"C{k}", ms=5, lw=0.8, label=f"fsi: {q}")
        for r, x, y in zip(e, t, err) if k == 0 else []:  # the other series share the grids
            ax.annotate(r["grid"], (x, y), xytext=(3, 3), textcoords="offset points", fontsize=6,
                        color=f"C{k}")
    markers = iter("s^vDP*X")
    for k, (peer, q) in enumerate(dict.fromkeys((p["peer"], p["quantity"]) for p in timed_peers)):
        ps = [p for p in timed_peers if p["quantity"] == q and p["peer"] == peer]
        ax.loglog([p["cpu_s"] for p in ps], [max(abs(p["error"]), 1e-16) for p in ps],
                  next(markers, "s") + "--", color=f"C{len(quantities) + k}", ms=5, lw=0.8,
                  mfc="none", label=f"{peer}: {q}")
    ax.set_xlabel("CPU time per run [s]" if key == "cpu_s" else
                  "wall time per run [s] (no CPU time recorded)")
    ax.set_ylabel("|error| (relative where the reference is nonzero)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(f"{name}: error against cost (labels: the runs' grids)" + (" (short mode)" if s.get("short") else ""),
                 fontsize=10)
    png = f"{name}_error_cpu.png"
    fig.savefig(os.path.join(dest, png), dpi=100)
    plt.close(fig)
    return png


def case_study(folder, name, dest):
    """A case's own error-against-cost study, folder/cost.png (turek-hron-cfd's `validate.py
    --cost`, turek-hron-fsi's cost.py), copied into dest: (file name, when written), or None."""
    src = os.path.join(folder, "cost.png")
    if not os.path.isfile(src):
        return None
    png = f"{name}_study_cost.png"
    shutil.copyfile(src, os.path.join(dest, png))
    return png, datetime.datetime.fromtimestamp(os.path.getmtime(src)).strftime("%Y-%m-%d %H:%M")


def bench_plots(bench, dest):
    """PNGs of the benchmarks that have JSON: {name: (png or None, JSON or error text)}."""
    made = {}
    for b in BENCHES:
        path = os.path.join(bench, f"{b}.json")
        if not os.path.exists(path):
            continue
        try:
            with open(path) as f:
                j = json.load(f)
        except ValueError as e:
            made[b] = (None, f"unreadable: {e}")
            continue
        png = None
        if b == "fluid" and j.get("grids"):
            g = j["grids"]
            fig, ax = plt.subplots(figsize=(7.5, 4), layout="constrained")
            x = np.arange(len(g))
            bottom = np.zeros(len(g))
            floor = np.array([r["poisson_floor_ms"] for r in g])
            for k, phase in enumerate(["predictor", "boundaries", "poisson", "projection"]):
                v = np.array([r["ms_per_step"].get(phase, 0.0) for r in g]) / floor
                ax.bar(x, v, 0.6, bottom=bottom, color=f"C{k}", label=phase)
                bottom += v
            total = np.array([r["ms_per_step"]["total"] for r in g]) / floor
            ax.plot(x, total, "kD", ms=5, label="whole step")
            ax.axhline(1.0, color="k", ls="--", lw=0.8, label="Poisson floor (FFT pair + tridiagonal)")
            for k, r in enumerate(g):
                ax.annotate(f"{total[k]:.2f}× ({r['ms_per_step']['total']:.3g} ms)", (k, total[k]),
                            xytext=(0, 5), textcoords="offset points", ha="center", fontsize=7)
            ax.set_xticks(x, [r["name"] for r in g], rotation=20, fontsize=7)
            ax.set_ylim(0, 1.45 * max(total.max(), bottom.max()))
            ax.set_ylabel("time per step / Poisson floor")
            ax.set_title("fluid step by phase, in units of its Poisson floor", fontsize=9)
            ax.legend(fontsize=7, loc="upper left", ncol=3)
            png = "bench_fluid.png"
        elif b == "coupled" and j.get("ms_per_step"):
            items = list(j["ms_per_step"].items())
            fig, ax = plt.subplots(figsize=(7.5, 0.3 * len(items) + 1.2), layout="constrained")
            y = np.arange(len(items))[::-1]
            ax.barh(y, [v for _, v in items], color=["C3" if k == "whole step" else "C0"
                                                     for k, _ in items])
            ax.set_yticks(y, [k for k, _ in items], fontsize=7)
            ax.set_xlabel("ms per coupled step")
            ax.set_title(f"coupled step at grid {j.get('grid')}: its phases ({j.get('steps')} steps)",
                         fontsize=9)
            png = "bench_coupled.png"
        elif b == "solid" and j.get("levels"):
            lv = j["levels"]
            fig, ax = plt.subplots(figsize=(6, 4), layout="constrained")
            nodes = [r["nodes"] for r in lv]
            for k, part in enumerate(["assembly", "factorization", "solve", "total"]):
                ax.loglog(nodes, [r["per_iteration_s"][part] * 1e3 for r in lv], "o-",
                          color=f"C{k}", label=part)
            ax.set_xlabel("nodes")
            ax.set_ylabel("ms per Newton iteration")
            ax.set_title("solid Newton iteration by phase", fontsize=9)
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3, which="both")
            png = "bench_solid.png"
        if png:
            fig.savefig(os.path.join(dest, png), dpi=100)
            plt.close(fig)
        made[b] = (png, j)
    return made


def _scalars(j, prefix=""):
    """The numbers and texts of a JSON object, flattened one level into (key, value) rows."""
    rows = []
    for k, v in j.items():
        if isinstance(v, (int, float, str)) and not isinstance(v, bool):
            rows.append((prefix + k, v))
        elif isinstance(v, dict) and not prefix:
            rows += _scalars(v, f"{k}: ")
    return rows


CSS = """body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:0.5em 0;font-size:0.85em}td,th{border:1px solid #ccc;
padding:2px 6px;text-align:left}th{background:#eee}.fail{color:#b00;font-weight:bold}
.pass{color:#070}.note{color:#666;font-size:0.85em}img{max-width:100%;border:1px solid #ddd}"""


def write(out, dest, runs_dir):
    """Write dest/index.html and its PNGs from out/ (case folders, out/bench); runs_dir: the
    runs/ folder (which cases exist). Returns the page's path."""
    os.makedirs(dest, exist_ok=True)
    m = machine()
    found = cases(out)
    known = sorted(os.path.basename(os.path.dirname(p))
                   for p in glob.glob(os.path.join(runs_dir, "*", "validate.py")))
    peer_rows = peers()
    h = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>fsi: speed against error"
         f"</title><style>{CSS}</style></head><body>",
         "<h1>Speed against error</h1>",
         f"<p>Machine: {m['cores']} cores, {html.escape(m['cpu'])}, {m['memory']}, load average {m['load']} "
         f"while this page was written (the timings below were taken when their runs ran; on a "
         f"shared machine compare CPU, not wall). "
         f"Written {m['date']} from commit <code>{html.escape(m['commit'])}</code>. Cases from "
         f"<code>{html.escape(out)}/&lt;case&gt;/summary.json</code> (<code>./fsi validate"
         f"</code>; short modes as marked), benchmarks from <code>out/bench/*.json</code> "
         f"(<code>./fsi bench</code>). CPU time is user + system of a case's jobs.</p>"]

    # The overview table.
    h.append("<h2>Cases</h2><table><tr><th>case</th><th>mode</th><th>verdict</th><th>judged "
             "metrics</th><th>jobs</th><th>wall s</th><th>CPU s</th><th>per-run data</th>"
             "<th>written</th></tr>")
    for c in sorted(set(known) | set(found)):
        s = found.get(c)
        if s is None:
            h.append(f"<tr><td>{c}</td><td colspan=8 class=note>not run: no "
                     f"out/{c}/summary.json</td></tr>")
            continue
        if "unreadable" in s:
            h.append(f"<tr><td>{c}</td><td colspan=8 class=fail>summary.json unreadable: "
                     f"{html.escape(s['unreadable'])}</td></tr>")
            continue
        judged = [v for v in s["metrics"].values() if v.get("pass") is not None]
        ok = sum(v["pass"] for v in judged)
        timed = bool(s.get("cpu_s")) or bool(s.get("wall_s"))
        verdict = "<span class=pass>pass</span>" if s.get("pass") else "<span class=fail>FAIL</span>"
        h.append(f"<tr><td><a href='#{c}'>{c}</a></td><td>{'short' if s.get('short') else 'full'}"
                 f"</td><td>{verdict}</td><td>{ok} of {len(judged)} pass</td>"
                 f"<td>{len(s.get('jobs', []))}</td>"
                 f"<td>{_fmt(s.get('wall_s'), '.1f') if timed else 'no timings'}</td>"
                 f"<td>{_fmt(s.get('cpu_s'), '.1f') if s.get('cpu_s') else 'no CPU time'}</td>"
                 f"<td>{'%d runs' % len(s['per_run']) if s.get('per_run') else 'none'}</td>"
                 f"<td>{s['written']}</td></tr>")
    h.append("</table>")

    # One section per case that ran.
    by_case = {}
    for p in peer_rows:
        by_case.setdefault(p["case"], []).append(p)
    for c in sorted(found):
        s = found[c]
        if "unreadable" in s:
            continue
        h.append(f"<h2 id='{c}'>{c}{' (short mode)' if s.get('short') else ''}</h2>")
        if s.get("reference_source"):
            h.append(f"<p>Reference: {html.escape(s['reference_source'])}.</p>")
        png = case_plot(c, s, by_case.get(c, []), dest)
        if png:
            h.append(f"<p><img src='{png}' alt='{c}: error against CPU time'></p>")
            h.append("<p class=note>One marker per run, labelled with its grid; this project's CPU "
                     "time is that of the whole run as the case script sets it up (to its t_end), "
                     "a peer's as its row in the table below says.</p>")
        study = case_study(os.path.dirname(s["path"]), c, dest)
        if study:
            h.append(f"<p>The case's own study of error against CPU time (its "
                     f"<code>cost.png</code>, written {study[1]}, by the mode its README names: "
                     f"the runs of every variant it has kept, not only this summary's):</p>"
                     f"<p><img src='{study[0]}' alt='{c}: its error-against-cost study'></p>")
        if not s.get("per_run"):
            h.append("<p class=note>This case's summary has no per-run entries (grid, Δt, error, "
                     "wall, CPU): no error-against-cost plot of its own runs. A case records them "
                     "with <code>metrics.finish(..., per_run=[metrics.run_entry(...)])</code>."
                     "</p>")
        else:
            h.append("<table><tr><th>run</th><th>quantity</th><th>grid</th><th>Δt</th><th>error"
                     "</th><th>reference</th><th>wall s</th><th>CPU s</th></tr>")
            for e in s["per_run"]:
                h.append(f"<tr><td>{_fmt(e.get('run'))}</td><td>{_fmt(e['quantity'])}</td>"
                         f"<td>{_fmt(e['grid'])}</td><td>{_fmt(e['dt'])}</td>"
                         f"<td>{_fmt(e['error'], '.3e')}</td><td>{_fmt(e.get('reference'))}</td>"
                         f"<td>{_fmt(e.get('wall_s'), '.2f')}</td>"
                         f"<td>{_fmt(e.get('cpu_s'), '.2f')}</td></tr>")
            h.append("</table>")
        orders = {k: v for k, v in s["metrics"].items() if "order" in k}
        if orders:
            h.append("<p>Observed order: " + "; ".join(
                f"{html.escape(k)} {_fmt(v['value'], '.3g')} (expected {_fmt(v['reference'], '.3g')})"
                for k, v in orders.items()) + ".</p>")
        h.append("<table><tr><th>metric</th><th>value</th><th>reference</th><th>error</th>"
                 "<th>tolerance</th><th>verdict</th></tr>")
        for k, v in s["metrics"].items():
            verdict = {True: "<span class=pass>pass</span>", False: "<span class=fail>FAIL</span>",
                       None: "reported"}[v.get("pass")]
            h.append(f"<tr><td>{html.escape(k)}</td><td>{_fmt(v.get('value'), '.6g')}</td>"
                     f"<td>{_fmt(v.get('reference'), '.6g')}</td><td>{_fmt(v.get('error'), '.3g')}"
                     f"</td><td>{_fmt(v.get('tolerance'), '.3g')}</td><td>{verdict}</td></tr>")
        h.append("</table>")
        if c in by_case:
            h.append(f"<p class=note>Peers' points on this plot: {len(by_case[c])} rows of "
                     "runs/lib/peers.csv (below).</p>")

    # Cases with a study of their own (cost.png) but no summary.
    for c in sorted(set(known) - set(found)):
        study = case_study(os.path.join(out, c), c, dest)
        if study:
            h.append(f"<h2 id='{c}-study'>{c} (no summary; its own study)</h2>"
                     f"<p>The case's study of error against CPU time (<code>out/{c}/cost.png"
                     f"</code>, written {study[1]}):</p>"
                     f"<p><img src='{study[0]}' alt='{c}: its error-against-cost study'></p>")

    # Cases with peers' numbers but no summary of their own.
    for c in sorted(set(by_case) - set(found)):
        h.append(f"<h2 id='{c}'>{c} (not run here)</h2>")
        png = case_plot(c, {}, by_case[c], dest)
        if png:
            h.append(f"<p><img src='{png}' alt='{c}: peers, error against CPU time'></p>")
        else:
            h.append("<p class=note>Only the peers' numbers, without timings (table below).</p>")

    h.append("<h2>Peers</h2><p>From <code>runs/lib/peers.csv</code> (its header says how they "
             "were measured): CPU is user + system of the whole run, single-threaded, on a 2-core "
             "Debian 12 machine like this one; treat ratios as ± 30 %.</p><table><tr><th>case"
             "</th><th>quantity</th><th>peer</th><th>grid</th><th>Δt</th><th>value</th><th>error"
             "</th><th>CPU s</th><th>source</th></tr>")
    for p in peer_rows:
        err = "–" if p["error"] is None else f"{100 * p['error']:+.2f} %"
        h.append(f"<tr><td>{p['case']}</td><td>{html.escape(p['quantity'])}</td><td>"
                 f"{html.escape(p['peer'])}</td><td>{html.escape(p['grid'])}</td><td>{p['dt']}</td>"
                 f"<td>{_fmt(p['value'])}</td><td>{err}</td><td>{_fmt(p['cpu_s'])}</td>"
                 f"<td>{html.escape(p['source'])}</td></tr>")
    h.append("</table>")

    # Benchmarks.
    bench = os.path.join(out, "bench")
    made = bench_plots(bench, dest)
    h.append("<h2>Per-step cost (./fsi bench)</h2>")
    missing = [b for b in BENCHES if b not in made]
    if missing:
        h.append("<p>Missing (no out/bench/&lt;name&gt;.json; run <code>./fsi bench NAME</code>): "
                 + ", ".join(missing) + ".</p>")
    for b, (png, j) in made.items():
        h.append(f"<h3>{b}</h3>")
        if isinstance(j, str):
            h.append(f"<p class=fail>{html.escape(j)}</p>")
            continue
        if png:
            h.append(f"<p><img src='{png}' alt='bench {b}'></p>")
        rows = _scalars(j)
        if rows:
            h.append("<table>" + "".join(f"<tr><td>{html.escape(k)}</td><td>{_fmt(v)}</td></tr>"
                                         for k, v in rows) + "</table>")
    h.append("</body></html>")
    page = os.path.join(dest, "index.html")
    with open(page, "w") as f:
        f.write("\n".join(h) + "\n")
    return page
