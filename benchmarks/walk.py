#!/usr/bin/env python
"""The walk of a ``qzs`` command through the package: which files it enters, and how often
it climbs back up the layers.

Run from the repository root with the project's interpreter and a warm numba cache (the
walk of a compile is numba's, not ours)::

    .venv/bin/python benchmarks/walk.py simulate --duration 5
    .venv/bin/python benchmarks/walk.py optimize isolation_vs_effort --generations 1 --population 4

Every Python call is recorded (``sys.setprofile``, in every thread; a compiled kernel's steps are not
Python calls and are not seen) and mapped to its file under ``src/qzs`` and that file's
layer (the table in ``qzs/__init__.py``, as ``tests/test_layers.py`` reads it). Printed:

- ``files entered``: the distinct files of ``qzs`` the command calls into;
- ``file changes``: consecutive calls in different files (the length of the walk);
- ``moves back up``: consecutive calls where the second is in a higher layer than the
  first: the command came down to a lower layer and went back up to continue from there
  (a value flowing up to be handed down again, or a callback);
- ``callbacks``: calls made from a lower layer's frame into a higher layer's function.

The command's output goes to a temporary folder (``--out`` is added unless given), and so
does the step cache (``QZS_CACHE_DIR``): a chosen step is chosen, not read back. The jobs a
command hands to a forked helper (:mod:`qzs.workflows.forked`: ``simulate``'s step choice,
its figure) run in this process, so that they are walked too.
"""
import os
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "src", "qzs")
BASE = "base"


def layers():
    """The layer of each top-level name, from the table in ``qzs/__init__.py``."""
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(ROOT)), "tests"))
    from test_layers import LAYERS, _layer_table  # noqa: E402 (the layout test's reading)

    table = {}
    for name in _layer_table():
        table[name] = name if name in LAYERS else BASE
    return LAYERS, table


def layer_index(path, order, table):
    relative = os.path.relpath(path, ROOT)
    first = relative.split(os.sep)[0]
    first = first[:-3] if first.endswith(".py") else first
    if first == "__init__" or first == "__main__":
        return order.index("cli") if first == "__main__" else 0
    return order.index(table.get(first, BASE))


def main(argv):
    order, table = layers()
    folder = tempfile.mkdtemp(prefix="qzs-walk-")
    os.chdir(folder)  # a figure written by default lands here, not in the checkout
    os.environ["QZS_CACHE_DIR"] = folder  # an empty step cache: the choice is walked
    if "--out" not in argv and argv and argv[0] in ("simulate", "optimize"):
        argv = [*argv, "--out", os.path.join(folder, "run.nc" if argv[0] == "simulate"
                                              else "out")]
    from qzs.cli import main as cli_main
    from qzs.workflows import forked

    forked.available = lambda: False  # the jobs a command forks (its step choice) run here

    calls = []

    def profile(frame, event, arg):
        if event != "call":
            return
        path = frame.f_code.co_filename
        if not path.startswith(ROOT):
            return
        caller = frame.f_back
        from_path = caller.f_code.co_filename if caller is not None else ""
        calls.append((path, from_path if from_path.startswith(ROOT) else None))

    import threading

    threading.setprofile(profile)  # the threads a command starts (a probe, a batch) too
    sys.setprofile(profile)
    try:
        code = cli_main(argv)
    except SystemExit as stop:
        code = stop.code
    finally:
        sys.setprofile(None)
        threading.setprofile(None)
    files = {path for path, _ in calls}
    changes = up = callbacks = 0
    previous = None
    for path, caller in calls:
        level = layer_index(path, order, table)
        if previous is not None and path != previous[0]:
            changes += 1
            if level > previous[1]:
                up += 1
        if caller is not None and layer_index(caller, order, table) < level:
            callbacks += 1
        previous = (path, level)
    print(f"qzs {' '.join(argv)}  (exit {code})")
    print(f"  calls            {len(calls)}")
    print(f"  files entered    {len(files)}")
    print(f"  file changes     {changes}")
    print(f"  moves back up    {up}")
    print(f"  callbacks        {callbacks}")
    if os.environ.get("QZS_WALK_FILES"):  # the files themselves, one per line
        for path in sorted(files):
            print("   ", os.path.relpath(path, ROOT))


if __name__ == "__main__":
    main(sys.argv[1:])
