#!/usr/bin/python3
"""A run stopped and restarted equals a run straight through, bit for bit.

  restart_same.py --scene SCENE --t-end T --bin BIN --work DIR [--stop half|signal] [--extra TOML]
                  [--fluid-ranks P] [--restart-ranks Q]

The scene is written beside itself with t_end = T (and `extra` appended) for the run straight
through; the stopped run is
  half:   the same scene with t_end = T/2 (its last step is checkpointed: checkpoint_interval
          is set to T/2), restarted with t_end = T;
  signal: the scene to T with checkpoints every T/4, sent SIGUSR1 (what ./fsi sends when asked
          to stop) after the first checkpoint appeared, so that it checkpoints at the step under way and stops there;
          then restarted to T.
Before the restart, a newer checkpoint folder that not every program completed is planted (a
crash while writing): the restart must pass it by. With --change 'OLD=>NEW' a restart of the
scene with that text replaced must first be refused with an error naming --key. With
--older-version copies of the checkpoint are first marked as written by older builds (the
fluid's file without a version; then the other programs' as version 7), one copy each: each
restart must be refused naming the version, the copy left as it was.
--effective resumes with the scene.effective.toml the stopped run wrote (its t_end made T, put
beside the scene): the scene as run, with every program's defaults filled in, is the same scene.
--fluid-ranks runs the stopped run's fluid on P ranks, --restart-ranks the restart's on Q (the
run straight through stays on one): a checkpoint holds the whole grid whatever the rank count.
Compared: every CSV file byte for byte and every numeric HDF5 dataset (compare_outputs.py), and
the XDMF files' step lists. Exits 1 naming the first difference, or when a run fails or a stop
did not happen before T.
"""
import argparse
import glob
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_outputs import command, compare_dirs, roles_of  # noqa: E402


def write_scene(scene, t_end, extra, tag, checkpoint_interval=None):
    text = open(scene).read()
    text, n = re.subn(r"(?m)^t_end\s*=.*$", f"t_end = {t_end!r}", text, count=1)
    if n != 1:
        sys.exit(f"restart_same: no t_end line in {scene}")
    if checkpoint_interval is not None:
        line = f"checkpoint_interval = {checkpoint_interval!r}"
        text, n = re.subn(r"(?m)^\[output\]\s*$", "[output]\n" + line, text, count=1)
        if n == 0:
            text += "\n[output]\n" + line + "\n"
    path = os.path.splitext(scene)[0] + f"_restart_{tag}_{os.getpid()}.toml"
    with open(path, "w") as f:
        f.write(text + "\n" + extra + "\n")
    return path


def run(bin_dir, scene, args, what, fluid_ranks=1):
    r = subprocess.run(command(bin_dir, scene, args, fluid_ranks), capture_output=True, text=True,
                       timeout=600)
    if r.returncode != 0:
        sys.exit(f"restart_same: the {what} failed (exit {r.returncode}):\n{r.stderr[-3000:]}")
    return r.stdout + r.stderr


def stop_by_signal(bin_dir, scene, out, fluid_ranks=1):
    """Start the run, send SIGUSR1 to mpirun once the first checkpoint exists, wait for it."""
    p = subprocess.Popen(command(bin_dir, scene, ["--out-dir", out, "--overwrite"], fluid_ranks),
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    deadline = time.monotonic() + 300
    while not glob.glob(os.path.join(out, "checkpoint", "step_*", "coupler.h5")) and p.poll() is None:
        if time.monotonic() > deadline:
            p.kill()
            sys.exit("restart_same: no checkpoint appeared")
        time.sleep(0.05)
    p.send_signal(signal.SIGUSR1)
    text, _ = p.communicate(timeout=300)
    if p.returncode != 0:
        sys.exit(f"restart_same: the signalled run failed (exit {p.returncode}):\n{text[-3000:]}")
    return text


def xdmf_times(folder):
    out = {}
    for path in sorted(glob.glob(os.path.join(folder, "*.xdmf"))):
        out[os.path.basename(path)] = re.findall(r'<Time Value="([^"]*)"', open(path).read())
    return out


def steps_of(out):
    """The steps of the complete-looking checkpoint folders of a run (step_<n>, n < 99999999)."""
    steps = [int(os.path.basename(p)[5:]) for p in glob.glob(os.path.join(out, "checkpoint", "step_*"))]
    return [n for n in steps if n < 99999999]


def snapshot(folder):
    """Every file under a folder with its size and modification time."""
    out = {}
    for root, _, files in os.walk(folder):
        for f in files:
            st = os.stat(os.path.join(root, f))
            out[os.path.join(root, f)] = (st.st_size, st.st_mtime_ns)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", required=True)
    ap.add_argument("--t-end", type=float, required=True)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--stop", choices=["half", "signal"], default="half")
    ap.add_argument("--extra", default="", help="TOML text appended to the scene (\\n: a new line)")
    ap.add_argument("--change", help="'OLD=>NEW': a scene text change the restart must refuse")
    ap.add_argument("--key", help="the key the refusal must name")
    ap.add_argument("--older-version", action="store_true",
                    help="checkpoints of older builds (no version, version 7) must be refused")
    ap.add_argument("--fluid-ranks", type=int, default=1, help="the stopped run's fluid ranks")
    ap.add_argument("--restart-ranks", type=int, help="the restart's fluid ranks (default: --fluid-ranks)")
    ap.add_argument("--effective", action="store_true",
                    help="resume with the stopped run's scene.effective.toml (its t_end made T)")
    a = ap.parse_args()
    a.extra = a.extra.replace("\\n", "\n")
    scene = os.path.abspath(a.scene)
    work = os.path.abspath(a.work)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    straight, stopped = os.path.join(work, "straight"), os.path.join(work, "stopped")
    made = []
    try:
        if a.stop == "half":
            full = write_scene(scene, a.t_end, a.extra, "full", a.t_end / 2)
            half = write_scene(scene, a.t_end / 2, a.extra, "half", a.t_end / 2)
            made += [full, half]
            run(a.bin, full, ["--out-dir", straight, "--overwrite"], "run straight through")
            run(a.bin, half, ["--out-dir", stopped, "--overwrite"], "run to T/2", a.fluid_ranks)
        else:
            full = write_scene(scene, a.t_end, a.extra, "full", a.t_end / 4)
            made.append(full)
            run(a.bin, full, ["--out-dir", straight, "--overwrite"], "run straight through")
            log = stop_by_signal(a.bin, full, stopped, a.fluid_ranks)
            steps = sorted(steps_of(stopped))
            print(f"restart_same: stopped by the signal; checkpoints at steps {steps}")
            with open(os.path.join(stopped, "summary.json")) as f:
                if "stopped_at_step" not in json.load(f):
                    sys.exit("restart_same: the signalled run did not stop early (it reached T first)")
        # A crash while writing the next checkpoint: a folder with some programs' files only.
        partial = os.path.join(stopped, "checkpoint", "step_99999999")
        os.makedirs(partial)
        open(os.path.join(partial, "coupler.h5.tmp"), "w").write("cut short")
        # (a scene of one program: its own file is the one cut short)
        alone = roles_of(a.bin, full) == ["fluid"]
        open(os.path.join(partial, "fluid.h5.tmp" if alone else "fluid.h5"), "w").write("not a checkpoint")
        if a.change:
            old, new = a.change.split("=>")
            text = open(full).read()
            if old not in text:
                sys.exit(f"restart_same: '{old}' is not in the scene")
            changed = os.path.splitext(full)[0] + "_changed.toml"
            made.append(changed)
            open(changed, "w").write(text.replace(old, new, 1))
            r = subprocess.run(command(a.bin, changed, ["--restart", stopped]), capture_output=True,
                               text=True, timeout=120)
            if r.returncode == 0 or f"{a.key} differs from the run being resumed" not in r.stderr:
                sys.exit(f"restart_same: the restart with {a.change} was not refused naming {a.key} "
                         f"(exit {r.returncode}):\n{r.stderr[-2000:]}")
            print(f"restart_same: a restart with {a.change} is refused naming {a.key}")
        if a.older_version:
            # On copies of the stopped run, files marked as written by older builds: the
            # fluid's without the version (before it was recorded), then the other programs' as
            # version 7. Every program checks its own file and the first to refuse ends the job,
            # so each mark is tried alone: with both at once, which message is printed is a race.
            import h5py
            step = max(steps_of(stopped))
            cases = [("fluid", "protocol version none recorded")]
            if roles_of(a.bin, full) != ["fluid"]:
                cases.append(("others", "protocol version 7,"))
            for marked, expected in cases:
                older = stopped + "_older"
                shutil.copytree(stopped, older)
                for p in glob.glob(os.path.join(older, "checkpoint", f"step_{step:08d}", "*.h5")):
                    is_fluid = os.path.basename(p) == "fluid.h5"
                    if is_fluid != (marked == "fluid"):
                        continue
                    with h5py.File(p, "r+") as h5:
                        if is_fluid:
                            del h5.attrs["protocol_version"]
                        else:
                            h5.attrs["protocol_version"] = 7
                before = snapshot(older)
                r = subprocess.run(command(a.bin, full, ["--restart", older]), capture_output=True,
                                   text=True, timeout=120)
                if r.returncode == 0 or expected not in r.stderr:
                    sys.exit(f"restart_same: a checkpoint of an older build ({marked} marked) was "
                             f"not refused saying '{expected}' (exit {r.returncode}):\n"
                             f"{r.stderr[-2000:]}")
                if snapshot(older) != before:
                    sys.exit("restart_same: the refused restart changed the output folder")
                shutil.rmtree(older)
            print("restart_same: checkpoints of older builds are refused, the output untouched")
        resume = full
        if a.effective:
            # The effective scene as the run wrote it, every program's defaults filled in: only
            # [time] t_end changed to the full run's. Beside the scene, whose folder its relative
            # file names (a mesh) are read from.
            resume = os.path.splitext(scene)[0] + f"_restart_effective_{os.getpid()}.toml"
            made.append(resume)
            table, lines = "", []
            for line in open(os.path.join(stopped, "scene.effective.toml")).read().splitlines():
                if line.startswith("["):
                    table = line.strip()
                if table == "[time]" and line.startswith("t_end ="):
                    line = f"t_end = {a.t_end!r}"
                lines.append(line)
            open(resume, "w").write("\n".join(lines) + "\n")
        log = run(a.bin, resume, ["--restart", stopped], "restart", a.restart_ranks or a.fluid_ranks)
        print(log.strip().splitlines()[-1] if log.strip() else "")
    finally:
        for p in made:
            os.remove(p)
    diff, n = compare_dirs(straight, stopped)
    if diff:
        sys.exit(f"restart_same: the restarted run differs: {diff}")
    if xdmf_times(straight) != xdmf_times(stopped):
        sys.exit(f"restart_same: the XDMF step lists differ: {xdmf_times(straight)} against {xdmf_times(stopped)}")
    print(f"restart_same: {n} files and datasets identical after the restart")


if __name__ == "__main__":
    main()
