"""Compose and run a job of the project's programs on a scene, as `./fsi run` does: the scene is
written into a work folder, the programs it needs come from `build/bin/fsi-plan`, one program runs
alone and several as one `mpirun` MPMD job (with --oversubscribe, and --allow-run-as-root when
root). Each run's wall time and CPU time (user + system of the job's processes) are kept in RUNS,
which metrics.finish() writes to the case's summary.json, and in the run's folder
(job_time.json), so that a run kept by `reuse` reports them again.
Environment (set by `./fsi validate`): FSI_ROOT, FSI_BIN, FSI_OUT; FSI_MPIRUN (default mpirun)."""
import collections
import json
import os
import re
import resource
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("FSI_ROOT", os.path.abspath(os.path.join(HERE, "..", "..")))
BIN = os.environ.get("FSI_BIN", os.path.join(ROOT, "build", "bin"))
MPIRUN = os.environ.get("FSI_MPIRUN", "mpirun")
# The case's output folder: FSI_OUT, else out/<case> at the root (out_dir sets it).
OUT = os.path.abspath(os.environ.get("FSI_OUT", os.path.join(os.getcwd(), "out")))

# folder, wall and CPU seconds, the job's exit code and its merged stdout/stderr ("" when reused).
Run = collections.namedtuple("Run", "folder wall cpu returncode log")
RUNS = []


def out_dir(case):
    """The case's output folder (FSI_OUT, else out/CASE at the root), created; also job.OUT."""
    global OUT
    OUT = os.path.abspath(os.environ.get("FSI_OUT", os.path.join(ROOT, "out", case)))
    os.makedirs(OUT, exist_ok=True)
    return OUT


def nest(*parts):
    """OUT/part/part/... for the parts that are not None or empty (a variant's outputs in a
    folder of their own), created; also job.OUT."""
    global OUT
    for part in parts:
        if part:
            OUT = os.path.join(OUT, part)
            os.makedirs(OUT, exist_ok=True)
    return OUT


def roles(scene):
    """The programs a scene file needs, as build/bin/fsi-plan says (its `programs:` line: the
    program of each role, e.g. solid-rigid for the solid role)."""
    r = subprocess.run([os.path.join(BIN, "fsi-plan"), scene], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"fsi-plan failed on {scene}:\n{r.stdout}{r.stderr}")
    for line in r.stdout.splitlines():
        if line.startswith("programs:"):
            return line.split(":", 1)[1].split()
    raise SystemExit(f"fsi-plan printed no programs for {scene}:\n{r.stdout}")


def command(scene, folder, programs):
    """The command line: the program alone, or one mpirun app context per program."""
    args = [scene, "--out-dir", folder, "--overwrite"]
    if len(programs) == 1:
        return [os.path.join(BIN, programs[0])] + args
    cmd = [MPIRUN, "--oversubscribe"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    for k, p in enumerate(programs):
        if k:
            cmd.append(":")
        cmd += ["-n", "1", os.path.join(BIN, p)] + args
    return cmd


def _children_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def same_defaults(folder):
    """Whether a finished run ran with today's defaults of the keys whose default changed: its
    effective scene records them (fluid.body_viscosity since the bodies became elastic by
    default; before, an unnamed key meant "kelvin-voigt"; fluid.implicit_forcing with
    Crank-Nicolson since "increment" became its default; before, "after_solve"); and, with
    rigid bodies under body_viscosity = "none", a build of protocol version 8 or later
    (summary.json; since version 8 "none" leaves rigid bodies their viscosity; runs before it
    record no version; a run without a summary yet is not judged on it); with several bodies
    under body_divergence = "solid" or "coupled_step", version 9 or later (since version 9 a
    cell whose faces name more than one body takes no divergence)."""
    path = os.path.join(folder, "scene.effective.toml")
    if not os.path.exists(path):
        return True
    text = open(path).read()
    if "[fluid]" not in text:
        return True
    def version_below(v):
        """Whether summary.json says a build before protocol version v (none yet: not judged)."""
        try:
            with open(os.path.join(folder, "summary.json")) as f:
                return json.load(f).get("protocol_version", 0) < v
        except OSError:
            return False
        except (ValueError, AttributeError):
            return True

    # (a key at a line's start, or inside an inline table)
    rigid = re.search(r'(^|[{,])\s*(kind\s*=\s*"rigid"|program\s*=\s*"solid-rigid")', text, re.M)
    if rigid and re.search(r'^body_viscosity\s*=\s*"none"', text, re.M) and version_below(8):
        return False
    dilating = re.search(r'^body_divergence\s*=\s*"(solid|coupled_step)"', text, re.M)
    if dilating and len(re.findall(r'^\[\[solid\.body\]\]', text, re.M)) > 1 and version_below(9):
        return False
    crank_nicolson = re.search(r'^diffusion\s*=\s*"implicit"', text, re.M) is not None
    return "body_viscosity" in text and (not crank_nicolson or "implicit_forcing" in text)


def run(name, scene_text, work=None, programs=None, check=True, reuse=False):
    """Write WORK/name.toml (WORK: the case's OUT) and run it into WORK/name: Run(folder, wall,
    cpu, returncode, log). programs: the roles, else fsi-plan's. check: a failed job stops the
    case with the end of its output. reuse: keep a finished run of the identical scene text."""
    work = os.path.abspath(work or OUT)
    os.makedirs(work, exist_ok=True)
    scene = os.path.join(work, name + ".toml")
    folder = os.path.join(work, name)
    done = os.path.join(folder, "summary.json")
    measured = os.path.join(folder, "job_time.json")  # this module's wall and CPU of the job
    if reuse and os.path.exists(done) and os.path.exists(scene) and open(scene).read() == scene_text \
            and same_defaults(folder):
        with open(done) as f:
            wall = json.load(f).get("wall_time", {})
        wall = max(wall.values()) if isinstance(wall, dict) and wall else float(wall or 0.0)
        cpu = None
        if os.path.exists(measured):  # the job's own measurement, when this module ran it
            with open(measured) as f:
                m = json.load(f)
            wall, cpu = m["wall_s"], m["cpu_s"]
        RUNS.append({"name": name, "wall_s": wall, "cpu_s": cpu, "reused": True})
        return Run(folder, wall, cpu, 0, "")
    with open(scene, "w") as f:
        f.write(scene_text)
    programs = list(programs or roles(scene))
    cpu0, t0 = _children_cpu(), time.time()
    r = subprocess.run(command(scene, folder, programs), cwd=work, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    wall, cpu = time.time() - t0, _children_cpu() - cpu0
    RUNS.append({"name": name, "programs": programs, "wall_s": wall, "cpu_s": cpu,
                 "exit": r.returncode})
    if r.returncode == 0 and os.path.isdir(folder):
        with open(measured, "w") as f:
            json.dump({"wall_s": wall, "cpu_s": cpu}, f)
    if check and r.returncode != 0:
        sys.stderr.write(r.stdout[-5000:])
        raise SystemExit(f"{name}: the job failed (exit {r.returncode}) on {scene}")
    return Run(folder, wall, cpu, r.returncode, r.stdout)


def first_error(log):
    """The first `ERROR` line of a job's output, else ""."""
    return next((ln for ln in log.splitlines() if "ERROR" in ln), "")
