"""``qzs optimize`` and ``qzs sensitivity``: the design space of a problem file."""
from pathlib import Path

from qzs.cli.common import (EPILOG, add_execution_options, add_output_options, check_output, emit,
                             integer_at_least, output_name, stopped)
from qzs.errors import ParameterError, Terminated
from qzs.iotools.paths import check_output_path

__all__ = ["add_parsers", "run_optimize_command", "run_sensitivity_command"]

_PROBLEM_HELP = ("design problem file (TOML), or a shipped problem name (e.g. "
                 "isolation_vs_effort); `qzs docs design-space` describes the layout")


def add_parsers(subparsers):
    """Add ``optimize`` and ``sensitivity`` to a sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``optimize`` parser.
    """
    cmd = subparsers.add_parser(
        "optimize", help="search a design problem for its Pareto set (NSGA-II)",
        description="Search the decision variables of a problem file for the designs that "
                    "best trade its objectives under its constraints (pymoo's NSGA-II; each "
                    "generation one lockstep batch), robust to its uncertain parameters. "
                    "Writes the store of every evaluated design, the Pareto set (.nc, .csv, "
                    ".mat), its figure, the chosen design as a run configuration "
                    "(chosen.toml, for qzs simulate --config) and a report.",
        epilog="The problem is checked before any run (unknown parameter or metric, empty "
               "bounds, infeasible constraints), and so is --out. Ctrl-C (130) and SIGTERM "
               "(143) keep every complete generation; --resume replays them and continues, "
               "with the same result as an uninterrupted run. " + EPILOG)
    cmd.add_argument("problem", metavar="FILE.toml", help=_PROBLEM_HELP)
    cmd.add_argument("--resume", action="store_true",
                     help="continue an interrupted search in --out (same problem file)")
    cmd.add_argument("--generations", type=integer_at_least(1), metavar="N",
                     help="generations (default the file's [optimizer] generations)")
    cmd.add_argument("--population", type=integer_at_least(1), metavar="N",
                     help="designs per generation (default the file's [optimizer] population)")
    cmd.add_argument("--seed", type=int, metavar="N",
                     help="seed of the search (default the file's [optimizer] seed); a "
                          "resumed search needs the seed and population it was started with")
    cmd.add_argument("--dry-run", action="store_true",
                     help="print the problem and the work, run nothing")
    add_execution_options(cmd, "evaluate")
    add_output_options(cmd, out=dict(metavar="DIR", unnamed="rename",
                                     help="output folder (default the problem's name); the "
                                          "store is DIR/NAME.zarr"))

    sens = subparsers.add_parser(
        "sensitivity", help="global sensitivity of a problem's metrics (Sobol or Morris)",
        description="Rank the decision variables and uncertain parameters of a problem file "
                    "by their influence on its metrics: Sobol first and total indices with "
                    "confidence intervals (SALib, Saltelli sampling), or Morris screening "
                    "for many parameters. Writes the indices (.nc, .csv, .mat) and a bar "
                    "chart with intervals.",
        epilog="The problem and --out are checked before any run. " + EPILOG)
    sens.add_argument("problem", metavar="FILE.toml", help=_PROBLEM_HELP)
    sens.add_argument("--method", choices=("sobol", "morris"),
                      help="default the file's [sensitivity] method")
    sens.add_argument("--samples", type=integer_at_least(1), metavar="N",
                      help="Sobol: base samples, a power of 2 (N x (d + 2) runs); Morris: "
                           "trajectories (N x (d + 1) runs); default the file's")
    sens.add_argument("--seed", type=int, metavar="N", help="default the file's")
    add_execution_options(sens, "evaluate")
    add_output_options(sens, out=dict(metavar="DIR", unnamed="replace",
                                      help="output folder (default NAME-sensitivity)"))
    return cmd


def _check_counts(args):
    from qzs._validation import seed
    from qzs.workflows.design_space.problem import MIN_POPULATION

    if args.seed is not None:
        seed("--seed", args.seed)
    for option in ("workers", "threads", "generations", "population", "samples"):
        value = getattr(args, option, None)
        least = MIN_POPULATION if option == "population" and value != 0 else 1
        if value is not None and value < least:
            reason = " (NSGA-II needs that many designs per generation)" if least > 1 else ""
            raise ParameterError(f"`--{option}` must be >= {least}, got {value}{reason}.")


def _search_flags(args):
    """The flags a resumed search must repeat (its seed and population), as typed."""
    return "".join(f" --{name} {getattr(args, name)}" for name in ("seed", "population")
                   if getattr(args, name) is not None)


def run_optimize_command(args):
    """Run ``qzs optimize`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs optimize`` arguments.

    Returns
    -------
    int
        0, or 130 if Ctrl-C interrupted the search, 143 if SIGTERM ended it (its complete
        generations stay in the store either way).
    """
    from qzs.workflows.design_space import load_problem, optimize, plan_text
    from qzs.workflows.design_space.result import file_writer
    from qzs.workflows.design_space.store import check, stored_generations

    _check_counts(args)

    problem = load_problem(args.problem)
    if args.dry_run:
        print(plan_text(problem))
        return 0
    folder, overwrite = output_name(args, "--out", args.out or problem.name, directory=True,
                                    resume=args.resume)
    store = folder / f"{problem.name}.zarr"
    check_output_path(folder, argument="--out", suffixes=None, directory=True,
                      overwrite=overwrite or args.resume or store.exists())  # see check
    check(store, resume=args.resume, overwrite=overwrite, argument="--out")
    quiet = args.quiet or args.json
    with file_writer(folder, progress=not quiet) as writer:  # its imports beside the search
        try:
            result = optimize(problem, store, resume=args.resume, overwrite=overwrite,
                              generations=args.generations, population=args.population,
                              seed=args.seed, scheduler=args.scheduler, workers=args.workers,
                              threads=args.threads, progress=not quiet)
        except (KeyboardInterrupt, Terminated) as stop:
            return stopped(stop, f"{stored_generations(store)} complete generation(s) are kept "
                                 f"in {store}. Continue with: qzs optimize {args.problem} --out "
                                 f"{folder} --resume{_search_flags(args)}")
        written = writer.write(result)
    emit(args, "\n".join([result.summary(), *(f"  wrote            {path}"
                                              for path in (store, *written))]),
         {"problem": problem.name, "summary": result.summary(),
          "files": [str(path) for path in (store, *written)]})
    return 0


def run_sensitivity_command(args):
    """Run ``qzs sensitivity`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs sensitivity`` arguments.

    Returns
    -------
    int
        0, or 130 if Ctrl-C interrupted it, 143 if SIGTERM ended it.
    """
    from qzs.workflows.design_space import load_problem
    from qzs.workflows.design_space.sensitivity import run_sensitivity

    _check_counts(args)
    problem = load_problem(args.problem)
    folder = Path(args.out) if args.out else Path(f"{problem.name}-sensitivity")
    check_output(args, "--out", folder, suffixes=None, directory=True)
    try:
        result, written = run_sensitivity(problem, folder, method=args.method,
                                          samples=args.samples, seed=args.seed,
                                          scheduler=args.scheduler, workers=args.workers,
                                          threads=args.threads,
                                          progress=not args.quiet and not args.json)
    except (KeyboardInterrupt, Terminated) as stop:
        return stopped(stop, "nothing is written (a sensitivity run is not resumable; fewer "
                             "--samples make it shorter)")
    emit(args, "\n".join([result.summary(), *(f"  wrote            {path}" for path in written)]),
         {"problem": problem.name, "summary": result.summary(),
          "files": [str(path) for path in written]})
    return 0
