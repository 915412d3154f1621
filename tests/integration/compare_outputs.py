#!/usr/bin/python3
"""Compare the results of two builds bit for bit, on scenes that cover every program and mode.

  compare_outputs.py --bin-a BUILD_A/bin --bin-b BUILD_B/bin --work DIR [--scenes NAME,...]
  compare_outputs.py --dirs OUT_A OUT_B

The first form runs each scene (shortened: t_end set below) with both builds' programs and
compares the two output folders; the second compares two existing output folders. Compared:
every CSV file byte for byte and every numeric dataset of every .h5 file value for value (NaN
equal to NaN). Timings (summary.json, progress lines) are not results and are not compared.
Exits 1 naming the first difference, when a run fails, or when a folder holds nothing to compare.
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# name: (scene, t_end or None for the scene's own, text appended). Together they cover the explicit step (default),
# coupled iterations with explicit diffusion (iterated) and with Crank-Nicolson (iterated-cn),
# contact (contact-drop, contact-blocks), fibers rooted on a body with Crank-Nicolson
# (fibers-on-block) and fibers in a channel (fiber-channel).
ITERATIONS = "\n[coupler.iterations]\nmax = 30\ntolerance = 1e-6\nrelaxation = 0.5\nreuse = 20\n"
SCENES = {
    "default": ("runs/default/scene.toml", 0.5, ""),
    "iterated": ("runs/equal-density/fsi1.toml", 0.25, ""),
    "iterated-cn": ("runs/neutral-disk/scene.toml", 0.3, ITERATIONS),
    "contact-drop": ("runs/contact-blocks/drop.toml", None, ""),
    "contact-blocks": ("runs/contact-blocks/blocks.toml", None, ""),
    "fibers-on-block": ("runs/fibers-on-block/scene.toml", 0.5, ""),
    "fiber-channel": ("runs/fiber-channel/scene.toml", 0.3, ""),
}


def h5_datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()])
                     if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fiu" else None)
    return out


def first_difference(a, b):
    """Where two CSV texts first differ: the line number and both lines (or which one ends)."""
    la, lb = a.decode(errors="replace").splitlines(), b.decode(errors="replace").splitlines()
    for n, (x, y) in enumerate(zip(la, lb), start=1):
        if x != y:
            return f"line {n}: {x[:200]!r} against {y[:200]!r}"
    if len(la) != len(lb):
        return f"{len(la)} lines against {len(lb)}"
    return "the same lines, other line ends"


def compare_dirs(first, second, new=None):
    """The first difference between two output folders as a message, or None; and the count of
    files and datasets compared. With `new` (a list), datasets that only the second folder's .h5
    files hold are appended to it instead of counting as a difference."""
    compared = 0
    names = lambda d, ext: sorted(os.path.basename(p) for p in glob.glob(os.path.join(d, ext)))
    for ext in ("*.csv", "*.h5"):
        if names(first, ext) != names(second, ext):
            return f"the folders hold other {ext} files: {names(first, ext)} against {names(second, ext)}", compared
    for name in names(first, "*.csv"):
        a = open(os.path.join(first, name), "rb").read()
        b = open(os.path.join(second, name), "rb").read()
        if a != b:
            return f"{name} differs: {first_difference(a, b)}", compared
        compared += 1
    for name in names(first, "*.h5"):
        d1 = h5_datasets(os.path.join(first, name))
        d2 = h5_datasets(os.path.join(second, name))
        if sorted(d1) != sorted(d2):
            missing, extra = sorted(set(d1) - set(d2)), sorted(set(d2) - set(d1))
            if missing or new is None:
                return f"{name} holds other datasets (missing {missing}, new {extra})", compared
            new += [f"{name}:{key}" for key in extra]
        for key, v in d1.items():
            if v.shape != d2[key].shape or not np.array_equal(v, d2[key], equal_nan=v.dtype.kind == "f"):
                return f"{name}:{key} differs", compared
            compared += 1
    if compared == 0:
        return "nothing to compare", compared
    return None, compared


def roles_of(bin_dir, scene):
    out = subprocess.run([os.path.join(bin_dir, "fsi-plan"), scene], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"compare_outputs: fsi-plan failed on {scene}:\n{out.stderr}")
    return re.search(r"^roles: (.*)$", out.stdout, re.M).group(1).split()


def command(bin_dir, scene, args, fluid_ranks=1):
    """The mpirun line of the programs a scene needs (fsi-plan), each given `args`; the fluid on
    `fluid_ranks` ranks."""
    cmd = ["mpirun", "--oversubscribe"]
    if os.geteuid() == 0:
        cmd.append("--allow-run-as-root")
    for k, p in enumerate(roles_of(bin_dir, scene)):
        if k:
            cmd.append(":")
        n = fluid_ranks if p == "fluid" else 1
        cmd += ["-n", str(n), os.path.join(bin_dir, p), scene] + list(args)
    return cmd


def run(bin_dir, scene, out):
    r = subprocess.run(command(bin_dir, scene, ["--out-dir", out, "--overwrite"]), capture_output=True,
                       text=True, timeout=900)
    if r.returncode != 0:
        sys.exit(f"compare_outputs: the run of {scene} with {bin_dir} failed (exit {r.returncode}):\n"
                 f"{r.stderr[-3000:]}")


def shortened(scene, t_end, extra):
    """The scene with t_end replaced and `extra` appended, written beside it (its relative mesh
    paths still hold)."""
    if t_end is None and not extra:
        return scene, False
    new = open(scene).read()
    if t_end is not None:
        new, n = re.subn(r"(?m)^t_end\s*=.*$", f"t_end = {t_end!r}", new, count=1)
        if n != 1:
            sys.exit(f"compare_outputs: no t_end line in {scene}")
    new += extra
    path = os.path.splitext(scene)[0] + "_compare.toml"
    with open(path, "w") as f:
        f.write(new)
    return path, True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin-a")
    ap.add_argument("--bin-b")
    ap.add_argument("--work", help="folder for the runs' outputs")
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated: " + ",".join(SCENES))
    ap.add_argument("--dirs", nargs=2, metavar=("OUT_A", "OUT_B"))
    ap.add_argument("--allow-new", action="store_true",
                    help="datasets that only B writes are listed, not counted as differences")
    a = ap.parse_args()
    new = [] if a.allow_new else None
    if a.dirs:
        diff, n = compare_dirs(*a.dirs, new)
        if diff:
            sys.exit(f"compare_outputs: {diff}")
        print(f"compare_outputs: {n} files and datasets identical")
        return
    if not (a.bin_a and a.bin_b and a.work):
        ap.error("--bin-a, --bin-b and --work are needed (or --dirs)")
    failed = []
    for name in a.scenes.split(","):
        if name not in SCENES:
            ap.error(f"unknown scene '{name}' (one of {', '.join(SCENES)})")
        scene, t_end, extra = SCENES[name]
        scene, temporary = shortened(os.path.join(ROOT, scene), t_end, extra)
        try:
            outs = []
            for tag, bin_dir in (("a", a.bin_a), ("b", a.bin_b)):
                out = os.path.join(os.path.abspath(a.work), name, tag)
                shutil.rmtree(out, ignore_errors=True)
                run(os.path.abspath(bin_dir), scene, out)
                outs.append(out)
        finally:
            if temporary:
                os.remove(scene)
        before = len(new) if new is not None else 0
        diff, n = compare_dirs(*outs, new)
        added = f" (new in B: {', '.join(sorted(set(new[before:])))})" if new and len(new) > before else ""
        print(f"{name}: " + (f"DIFFERS: {diff}" if diff else f"{n} files and datasets identical{added}"))
        if diff:
            failed.append(name)
    if failed:
        sys.exit(f"compare_outputs: {', '.join(failed)} differ")


if __name__ == "__main__":
    main()
