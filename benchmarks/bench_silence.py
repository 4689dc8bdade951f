#!/usr/bin/env python
"""The longest silence of qzs's long commands on a terminal (issue 32: none over 2 s).

    .venv/bin/python benchmarks/bench_silence.py                 # every command, 80 and 0 columns
    .venv/bin/python benchmarks/bench_silence.py --only optimize --columns 0

Each command runs in a pseudo-terminal (``pty``) of the given size, as in a console: 80
columns (tqdm's bars) and 0 columns (some CI and IDE consoles, where qzs prints plain
lines). The output is read as it comes; the report gives, per command and size, the time
to the first byte, the longest stretch with no byte at all (and when it ended), the whole
wall time and the exit code. The commands run in a temporary folder with ``--overwrite``
where they write; numba's cache is the normal one (warm after a first run). Exits 0: a
benchmark reports, it does not fail CI. The machine's load is printed before each run.
"""
import argparse
import fcntl
import os
import pty
import select
import struct
import subprocess
import sys
import tempfile
import termios
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON = sys.executable
LIMIT = 2.0  # [s] the longest silence issue 32 allows

#: name -> the command line after ``python -m qzs``
COMMANDS = {
    "design --quick": ["design", "--quick", "--overwrite"],
    "paper --quick": ["paper", "--quick", "--overwrite"],
    "hexapod study --quick": ["hexapod", "study", "--quick", "--overwrite"],
    "optimize": ["optimize", "isolation_vs_effort", "--overwrite"],
    "simulate": ["simulate", "--out", "run.nc", "--overwrite"],
}


def silences(argv, columns, cwd):
    """Run ``argv`` on a pty of ``columns`` x 24; returns (first, longest, ended_at, wall, rc)."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}
    start = time.perf_counter()
    process = subprocess.Popen(argv, stdin=slave, stdout=slave, stderr=slave, cwd=cwd, env=env,
                               close_fds=True)
    os.close(slave)
    first, last, longest, ended = None, start, 0.0, 0.0
    while True:
        ready, _, _ = select.select([master], [], [], 0.02)
        if ready:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the pty closes when the child ends
                break
            if not chunk:
                break
            now = time.perf_counter()
            first = now - start if first is None else first
            if now - last > longest:
                longest, ended = now - last, now - start
            last = now
        elif process.poll() is not None:
            break
    code = process.wait()
    wall = time.perf_counter() - start
    if wall - (last - start) > longest:  # a silence before the end counts too
        longest, ended = wall - (last - start), wall
    os.close(master)
    return first, longest, ended, wall, code


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", default=None, help="command names (see the table)")
    parser.add_argument("--columns", type=int, nargs="*", default=[80, 0])
    args = parser.parse_args()
    names = [n for n in COMMANDS if args.only is None or any(o in n for o in args.only)]
    print(f"{'command':24s} {'cols':>4s} {'first':>7s} {'longest':>8s} {'ends at':>8s} "
          f"{'wall':>7s}  rc  verdict   (load before)")
    with tempfile.TemporaryDirectory() as folder:
        for name in names:
            for columns in args.columns:
                load = os.getloadavg()[0]
                first, longest, ended, wall, code = silences(
                    [PYTHON, "-m", "qzs", *COMMANDS[name]], columns, folder)
                verdict = "PASS" if longest <= LIMIT else "FAIL"
                print(f"{name:24s} {columns:4d} {first or float('nan'):6.2f}s {longest:7.2f}s "
                      f"{ended:7.1f}s {wall:6.1f}s {code:3d}  {verdict}      ({load:.1f})",
                      flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
