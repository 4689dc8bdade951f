"""``qzs paper`` and ``qzs study``: the paper's studies, their figures, metrics and report."""
from pathlib import Path

from qzs.cli.common import (add_frequency_axis_option, add_output_options, add_spring_option,
                             check_output, emit, integer_at_least)
from qzs.defaults import ACCURACY

__all__ = ["add_parsers", "run"]


def add_parsers(subparsers):
    """Add ``paper`` and ``study`` to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.
    """
    for name, text in (("paper", "run every study of the paper, write figures, metrics and "
                                 "report.html"),
                       ("study", "run one study definition (a shipped name or a TOML file)")):
        cmd = subparsers.add_parser(name, help=text, description=text)
        if name == "study":
            cmd.add_argument("definition", metavar="FILE.toml",
                             help="study file, or a shipped study name (e.g. stiction); or "
                                  "one of the paper's open questions: friction_compensation, "
                                  "damping_design (`qzs docs questions`)")
        cmd.add_argument("--quick", action="store_true",
                         help="shorter runs (fewer, shorter Welch segments)")
        step = cmd.add_mutually_exclusive_group()
        step.add_argument("--dt", type=float, metavar="S",
                          help="integration step [s] of every case, as given (the paper's: "
                               "1e-4); default chosen for --tolerance")
        step.add_argument("--tolerance", type=float, metavar="DB",
                          help="choose one step per batch of cases, the largest keeping every "
                               "case's transmissibility within DB [dB] (default "
                               f"{ACCURACY['tolerance_db']:g}; `qzs docs model` §7); a study "
                               "file's [simulation] dt is kept")
        cmd.add_argument("--workers", type=integer_at_least(1), metavar="N",
                         help="worker processes (default: all cores)")
        add_frequency_axis_option(cmd)
        add_spring_option(cmd, config=False)
        if name == "paper":
            out = dict(metavar="DIR", default="results/paper",
                       help="output folder (default results/paper)")
        else:
            out = dict(metavar="DIR", help="output folder (default results/NAME, NAME the "
                                           "study's, e.g. results/stiction)")
        add_output_options(cmd, out=dict(out, unnamed="replace"))


def run(args):
    """Run ``qzs paper`` or ``qzs study`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs paper`` or ``qzs study`` arguments (``args.command`` tells which).

    Returns
    -------
    int
        The exit code, 0.
    """
    from qzs.iotools.config import load_spring
    from qzs.workflows.paper.report import paper_summary, run_paper
    from qzs.workflows.paper.report_spring import spring_statement
    from qzs.workflows.paper.report_step import step_statement
    from qzs.workflows.questions import QUESTIONS

    if args.command == "study" and args.definition in QUESTIONS \
            and not Path(args.definition).exists():
        return _question(args)
    if args.out is None:  # qzs study: the study's own folder, so that two never share one
        args.out = f"results/{Path(args.definition).stem}"
    check_output(args, "--out", args.out, suffixes=None, directory=True)
    spring = None if args.spring is None else load_spring(args.spring)
    definitions = None if args.command == "paper" else [args.definition]
    results, verdicts, wall = run_paper(definitions, args.out, quick=args.quick,
                                        workers=args.workers,
                                        progress=not args.quiet and not args.json,
                                        argument="--out", dt=args.dt,
                                        tolerance=args.tolerance,
                                        frequency_scale=args.frequency_axis,
                                        spring=spring)
    lines = [f"{result.study.name:<12} {len(result.cases):>2} case(s) {result.seconds:7.1f} s"
             for result in results]
    lines.append(f"{'total':<12}    wall {wall:7.1f} s")
    lines.append(f"spring: {spring_statement(results)}")
    lines.append(step_statement(results))
    lines.extend(f"  [{verdict.label}] {verdict.statement} ({verdict.study})\n"
                 f"      {verdict.evidence}" for verdict in verdicts)
    lines.append(f"wrote {Path(args.out) / 'report.html'}, metrics.json, metrics.csv, figures and "
                 "their curves (<study>_curves.nc, .csv, .mat)")
    emit(args, "\n".join(lines),
         paper_summary(results, verdicts, args.out, quick=args.quick, wall_seconds=wall))
    return 0


def _question(args):
    """``qzs study friction_compensation`` or ``damping_design``: an open question's study."""
    from qzs.errors import ParameterError

    if args.spring is not None:
        raise ParameterError(f"--spring {args.spring!r} applies to the paper's studies; "
                             f"{args.definition!r} is one of the paper's open questions, "
                             "whose study runs the paper's MagSpring: leave --spring out.",
                             ("--spring",))
    from qzs.workflows.questions import run_question

    if args.tolerance is not None:
        raise ParameterError(f"--tolerance {args.tolerance!r}: the study {args.definition!r} "
                             "runs at one given step; give --dt S instead (default 1e-4 s).",
                             "--tolerance")
    if args.out is None:
        args.out = f"results/{args.definition}"
    check_output(args, "--out", args.out, suffixes=None, directory=True)
    result, written, wall = run_question(args.definition, args.out, quick=args.quick,
                                         dt=1e-4 if args.dt is None else args.dt,
                                         workers=args.workers,
                                         progress=not args.quiet and not args.json)
    answer = result["answer"]
    lines = [f"{args.definition}: wall {wall:.1f} s", f"  [{answer.label}] {answer.answer}",
             f"      {answer.evidence}",
             "wrote " + ", ".join(str(path) for path in written.values())]
    emit(args, "\n".join(lines), {"study": args.definition, "quick": args.quick,
                                   "wall_seconds": wall, "answer": answer.to_dict(),
                                   "files": {k: str(v) for k, v in written.items()}})
    return 0
