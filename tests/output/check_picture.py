#!/usr/bin/python3
"""The generic picture of a run folder: runs/plot_run.py FOLDER exits 0, says it shows what
--expect names, and its picture.png is a real picture (not blank).

usage: check_picture.py FOLDER --expect TEXT   |   check_picture.py --self-test
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def png_problems(path, min_size=300):
    """What is wrong with a PNG that should hold a picture: missing, small, or blank (fewer than 5 %
    of its pixels differ from its commonest colour, or fewer than 16 colours)."""
    if not os.path.exists(path):
        return [f"missing {path}"]
    img = mpimg.imread(path)[..., :3]
    h, w = img.shape[:2]
    out = []
    if min(h, w) < min_size:
        out.append(f"{path}: {w} x {h} pixels, smaller than {min_size}")
    flat = (np.round(img.reshape(-1, 3) * 255)).astype(np.int32)
    codes = flat[:, 0] * 65536 + flat[:, 1] * 256 + flat[:, 2]
    values, counts = np.unique(codes, return_counts=True)
    other = 1 - counts.max() / codes.size
    print(f"{path}: {w} x {h}, {len(values)} colours, {100 * other:.1f} % off the commonest")
    if other < 0.05 or len(values) < 16:
        out.append(f"{path} is blank: {len(values)} colours, {100 * other:.1f} % of pixels off the "
                   "commonest colour")
    return out


def self_test():
    """A blank and a nearly blank PNG must be rejected, a drawn one accepted."""
    with tempfile.TemporaryDirectory() as tmp:
        blank = os.path.join(tmp, "blank.png")
        plt.imsave(blank, np.ones((400, 600, 3)))
        dot = os.path.join(tmp, "dot.png")
        img = np.ones((400, 600, 3))
        img[190:210, 290:310] = 0
        plt.imsave(dot, img)
        drawn = os.path.join(tmp, "drawn.png")
        x = np.linspace(0, 6, 600)
        plt.imsave(drawn, np.sin(x)[None, :] * np.cos(x[:400])[:, None], cmap="RdBu_r")
        bad = []
        if not png_problems(blank):
            bad.append("a blank PNG passed")
        if not png_problems(dot):
            bad.append("a PNG with one small dot passed")
        if png_problems(drawn):
            bad.append("a drawn PNG failed")
        return bad


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folder", nargs="?")
    p.add_argument("--expect", default="", help="a regular expression the 'shows:' text must match")
    p.add_argument("--self-test", action="store_true")
    a = p.parse_args()
    if a.self_test:
        bad = self_test()
    else:
        png = os.path.join(a.folder, "picture.png")
        if os.path.exists(png):
            os.remove(png)
        r = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "runs", "plot_run.py"), a.folder],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        print(r.stdout)
        bad = [] if r.returncode == 0 else [f"plot_run.py exited {r.returncode}"]
        shows = re.search(r"\((shows: .*)\)", r.stdout)
        if not shows or not re.search(a.expect, shows.group(1)):
            bad.append(f"plot_run.py's 'shows:' text does not match /{a.expect}/")
        bad += png_problems(png)
    for b in bad:
        print("FAIL:", b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
