#!/usr/bin/python3
"""A movie of a run folder: every output step drawn as runs/lib/picture.py draws the last one
(the fluid field, the bodies' meshes, the fibers, the probes' histories with the time marked),
the frames encoded by ffmpeg into OUT_DIR/movie.mp4 (H.264). `./fsi movie OUT_DIR` installs
ffmpeg and calls this.

usage: movie.py OUT_DIR [--fps N] [--dpi N] [--output FILE]
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib"))
import cli  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import picture  # noqa: E402


def main():
    p = cli.parser(__doc__, short=False)
    p.add_argument("out", help="the run's output folder")
    p.add_argument("--fps", type=cli.positive, default=None,
                   help="frames per second (default: the movie lasts about 8 s, 2 to 25 fps)")
    p.add_argument("--dpi", type=int, default=100, help="resolution of the frames")
    p.add_argument("--output", default=None, help="the MP4 file (default OUT_DIR/movie.mp4)")
    a = p.parse_args()
    if not os.path.isdir(a.out):
        raise SystemExit(f"movie.py: no output folder {a.out}")
    ffmpeg = shutil.which("ffmpeg")
    if not ffmpeg:
        raise SystemExit("movie.py: ffmpeg not found (sudo apt-get install ffmpeg, or ./fsi movie)")
    run = picture.Run(a.out)
    n = len(run.times)
    fps = a.fps or min(25.0, max(2.0, n / 8.0))
    mp4 = os.path.abspath(a.output or os.path.join(a.out, "movie.mp4"))
    with tempfile.TemporaryDirectory(prefix="fsi-movie-") as tmp:
        for k in range(n):
            fig = picture.draw(run, k, cursor=True)
            fig.savefig(os.path.join(tmp, f"frame_{k:05d}.png"), dpi=a.dpi)
            plt.close(fig)
            print(f"\rframe {k + 1}/{n}", end="", flush=True)
        print()
        # yuv420p (what players expect) needs even width and height.
        cmd = [ffmpeg, "-y", "-loglevel", "error", "-framerate", f"{fps:g}", "-i",
               os.path.join(tmp, "frame_%05d.png"), "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2:color=white",
               "-c:v", "libx264", "-pix_fmt", "yuv420p", "-movflags", "+faststart", mp4]
        r = subprocess.run(cmd)
        if r.returncode != 0:
            raise SystemExit(f"movie.py: ffmpeg failed (exit {r.returncode}): {' '.join(cmd)}")
    print(f"movie: {mp4} ({n} frames, {fps:g} fps)")


if __name__ == "__main__":
    main()
