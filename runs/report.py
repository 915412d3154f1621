#!/usr/bin/python3
"""Speed against error on one page: gathers each validated case's summary.json (OUT/<case>/, as
`./fsi validate` writes them), the benchmarks' JSON (OUT/bench/*.json, `./fsi bench`) and the
peers' numbers (runs/lib/peers.csv) into DEST/index.html with PNG plots (runs/lib/report.py).
`./fsi report` calls it with OUT = out/.

usage: report.py [--out OUT] [--dest DEST]
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "lib"))
import cli  # noqa: E402
import report  # noqa: E402


def main():
    p = cli.parser(__doc__, short=False)
    p.add_argument("--out", default=os.path.join(HERE, "..", "out"),
                   help="the folder of the cases' output folders (default: out/ at the root)")
    p.add_argument("--dest", default=None, help="where the page goes (default OUT/report)")
    a = p.parse_args()
    out = os.path.abspath(a.out)
    if not os.path.isdir(out):
        raise SystemExit(f"report.py: no folder {out} (run ./fsi validate first)")
    page = report.write(out, os.path.abspath(a.dest or os.path.join(out, "report")), HERE)
    print(f"report: {page}")


if __name__ == "__main__":
    main()
