#!/usr/bin/python3
"""Floating stacks at growing size: n blocks of 4 x 4 Q1 cells stacked downwards, each on a
roller on its left side (free along y: held only by its contacts), the lowest clamped at the
bottom, the top one pressed by 1e6 Pa; one run per n, its phase times and peak memory as
printed by the program. The set-up of the floating groups' checks is the assemble phase.

  /usr/bin/python3 bench/bench_floating_stack.py [--bin bin/robin_contact] [N ...]

(default N: 1000 2000 4000 8000; about 1 minute in all on 2 cores). Reports, asserts nothing.
"""
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from rc_run import tool_parser  # noqa: E402


def deck(n, path):
    lines = ["&scene title='floating stack' /"]
    for k in range(1, n + 1):
        bc = ", bottom='clamped'" if k == n else ", left='roller'"
        lines.append(f"&body id={k}, x0=0.0, y0={float(n - k)}, width=1.0, height=1.0, nx=4, ny=4{bc} /")
    lines.append("&traction body=1, side='top', t0=0.0, -1.0e6 /")
    lines += [f"&contact bodies={k},{k + 1}, groups='bottom','top' /" for k in range(1, n)]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = tool_parser(__doc__)
    ap.add_argument("sizes", nargs="*", type=int, default=[1000, 2000, 4000, 8000])
    a = ap.parse_args()
    binary = os.path.abspath(a.bin)
    print("| blocks | assemble [s] | factor [s] | iterate [s] | output [s] | total [s] | peak [MB] | outer |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory(prefix="rc_floating_stack_") as work:
        for n in a.sizes:
            path = os.path.join(work, f"stack{n}.nml")
            deck(n, path)
            p = subprocess.run([binary, path, f"&output file='{work}/s{n}.h5' /"], capture_output=True, text=True,
                               cwd=work)
            t = dict(re.findall(r"(\w+)=([\d.]+)", next((ln for ln in p.stdout.splitlines()
                                                          if ln.startswith("time:")), "")))
            outer = re.search(r"^result: .* outer=(\d+)", p.stdout, re.M)
            print(f"| {n} | {t.get('assemble', '?')} | {t.get('factor', '?')} | {t.get('iterate', '?')} | "
                  f"{t.get('output', '?')} | {t.get('total', '?')} | {t.get('peak_mb', '?')} | "
                  f"{outer.group(1) if outer else 'exit ' + str(p.returncode)} |", flush=True)


if __name__ == "__main__":
    main()
