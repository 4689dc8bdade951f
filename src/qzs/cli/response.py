"""``qzs response``: the steady-state frequency response by stepped-sine simulation.

It parses and delegates to :func:`qzs.workflows.response.steady_state_response`
(docs/response.md); ``--json`` prints the list of points, one record each.
"""
from pathlib import Path

from qzs.cli.common import (add_frequency_axis_option, add_output_options, add_set_option,
                             check_output, emit, figure_path, integer_at_least, parameters)
from qzs.defaults import EXCITATION
from qzs.errors import ParameterError

__all__ = ["add_parser", "run", "parse_frequencies", "DEFAULT_RANGE"]

DEFAULT_PLOT = "qzs-response.png"
#: Formats ``--plot`` writes (matplotlib chooses by the extension).
PLOT_SUFFIXES = (".png", ".svg", ".pdf")
#: Default frequencies: 40 from 0.5 to 20 Hz (the paper's band above the locked region).
DEFAULT_RANGE = (0.5, 20.0, 40)


def add_parser(subparsers):
    """Add ``response`` to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``response`` parser.
    """
    parser = subparsers.add_parser(
        "response", help="steady-state frequency response (stepped sine, harmonic balance)",
        description="Simulate each frequency until the response is periodic, sweeping up and "
                    "down (each frequency starts from the last one's state), and report the "
                    "fundamental transmissibility (payload over base acceleration), the "
                    "harmonics, the relative amplitude, the locked share of the period and the "
                    "stop contacts; the harmonic balance of the smooth model is drawn over it "
                    "(`qzs docs response`). Without options: 40 log-spaced frequencies from "
                    "0.5 to 20 Hz, 10 mm, both sweeps, the step chosen for 0.01 dB.")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--frequencies", metavar="F1,F2,...",
                       help="the frequencies [Hz], comma-separated, increasing (the sweeps "
                            "go up and down over them: --direction)")
    where.add_argument("--range", metavar="F0,F1,N",
                       help="N frequencies from F0 to F1 [Hz] (default 0.5,20,40)")
    parser.add_argument("--spacing", choices=("log", "linear"),
                        help="spacing of a --range (default log)")
    parser.add_argument("--amplitude", type=float, metavar="M",
                        help="base displacement amplitude [m] (default the config's, else "
                             f"{EXCITATION['amplitude']:.3f})")
    parser.add_argument("--config", metavar="FILE.toml",
                        help="run configuration (see `qzs params --toml`)")
    add_set_option(parser)
    parser.add_argument("--direction", choices=("up", "down", "both"), default="both",
                        help="sweeps: up, down or both (default; in parallel)")
    step = parser.add_mutually_exclusive_group()
    step.add_argument("--dt", type=float, metavar="S",
                      help="largest integration step [s] (each frequency uses the largest step "
                           "at most this with whole samples per period)")
    step.add_argument("--tolerance", type=float, metavar="DB",
                      help="choose the step for this accuracy [dB] on a chirp over the band "
                           "(default 0.01; `qzs docs model` §7)")
    parser.add_argument("--solver", choices=("ode3", "rk4", "euler"),
                        help="integrator (default ode3)")
    parser.add_argument("--periodic-tolerance", type=float, metavar="X",
                        help="periodicity tolerance: scaled state change per period "
                             "(default 1e-6)")
    parser.add_argument("--max-periods", type=integer_at_least(8), metavar="N",
                        help="periods at most per frequency before it is reported not "
                             "periodic (default 100000, a safety; --max-time usually ends it)")
    parser.add_argument("--max-time", type=float, metavar="S",
                        help="simulated time at most per frequency [s] (default 30 of the "
                             "linearised loop's slowest time constants, within 60-3600 s; "
                             "115 s for the paper's loop)")
    parser.add_argument("--harmonics", type=integer_at_least(2), metavar="N",
                        help="highest harmonic reported (default 5)")
    parser.add_argument("--no-harmonic-balance", action="store_true",
                        help="skip the harmonic balance of the smooth model")
    parser.add_argument("--friction-velocity", type=float, metavar="M_PER_S",
                        help="regularisation velocity of the harmonic balance's friction "
                             "[m/s] (default 0.001)")
    parser.add_argument("--compare-chirp", action="store_true",
                        help="also simulate the paper's chirp (0.01 Hz/s) and draw its Welch "
                             "estimate beside the steady state")
    parser.add_argument("--workers", type=integer_at_least(1), metavar="N",
                        help="processes (default: the sweeps and extra tasks, at most the cores)")
    add_frequency_axis_option(parser)
    add_output_options(parser, out=dict(metavar="FILE", help="write the response to FILE (.nc, "
                                                            ".csv, .json or .mat)"),
                       plot=dict(default=DEFAULT_PLOT, help="figure, its curve written beside "
                                                            "it as .nc, .csv and .mat"),
                       json_help="print the points as a JSON list of records (frequency [Hz], "
                                 "transmissibility [-], direction, ...; NaN as null) instead "
                                 "of the table; notes go to stderr")
    return parser


def parse_frequencies(frequencies=None, frequency_range=None, spacing=None):
    """The frequencies of ``--frequencies`` or ``--range`` (default :data:`DEFAULT_RANGE`).

    What was typed is taken as it is or refused, never silently changed: a list out of
    order or with a repeat, and a ``--spacing`` without ``--range``, are errors.

    Parameters
    ----------
    frequencies : str, optional
        ``"F1,F2,..."`` [Hz], increasing.
    frequency_range : str, optional
        ``"F0,F1,N"``: N frequencies from F0 to F1 [Hz].
    spacing : {"log", "linear"}, optional
        Spacing of a range; default log.

    Returns
    -------
    list of float
        The frequencies [Hz] (the workflow checks that they are positive and finite).

    Raises
    ------
    ParameterError
        Text that is not numbers, a list that is not increasing, a range that is not
        ``F0,F1,N`` with ``N >= 1``, ``spacing`` with a list;
        :class:`~qzs.errors.CountLimitError` for more than
        :data:`qzs.workflows.response.sweep.MAX_FREQUENCIES` (before any is made).
    """
    import numpy as np

    from qzs.errors import CountLimitError
    from qzs.workflows.response.sweep import MAX_FREQUENCIES

    if frequencies is not None:
        if spacing is not None:
            raise ParameterError(f"--spacing {spacing} spaces a --range; --frequencies "
                                 f"{frequencies} lists them: leave out --spacing, or give "
                                 "--range F0,F1,N instead.")
        try:
            values = [float(item) for item in frequencies.split(",") if item.strip()]
        except ValueError:
            raise ParameterError(f"--frequencies must be numbers in Hz separated by commas, "
                                 f"got {frequencies!r}; e.g. --frequencies 1,2,5.") from None
        for before, after in zip(values, values[1:]):
            if after <= before:
                what = (f"{after:g} Hz is given twice" if after == before
                        else f"{after:g} Hz comes after {before:g} Hz")
                raise ParameterError(
                    f"--frequencies {frequencies} must be increasing, each once: {what}; "
                    f"give them in increasing order, e.g. --frequencies "
                    f"{','.join(f'{v:g}' for v in sorted(set(values)))} (the sweeps go up "
                    "and down over them: --direction).")
        return values
    if frequency_range is None:
        low, high, count = DEFAULT_RANGE
    else:
        parts = frequency_range.split(",")
        try:
            low, high, count = float(parts[0]), float(parts[1]), int(parts[2])
            if len(parts) != 3 or count < 1:
                raise ValueError
        except (ValueError, IndexError):
            raise ParameterError(
                f"--range must be F0,F1,N (two frequencies in Hz and a count >= 1), got "
                f"{frequency_range!r}; e.g. --range 0.5,20,40.") from None
        if not (np.isfinite(low) and np.isfinite(high) and 0 < low <= high):
            raise ParameterError(f"--range needs 0 < F0 <= F1 (finite, Hz), got "
                                 f"{frequency_range!r}; e.g. --range 0.5,20,40.")
        if count > MAX_FREQUENCIES:
            raise CountLimitError("--range", count, MAX_FREQUENCIES, "frequencies",
                                  "give a smaller N, or split the band into several responses")
    if count == 1:
        return [low]
    grid = (np.linspace(low, high, count) if spacing == "linear"
            else np.geomspace(low, high, count))
    return [float(f) for f in grid]


def run(args):
    """Run ``qzs response`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs response`` arguments.

    Returns
    -------
    int
        The exit code, 0 (points that did not settle are NaN with their reason).
    """
    import sys

    from qzs.workflows.paper.curves import CURVE_SUFFIXES
    from qzs.workflows.response import RESPONSE_SUFFIXES, steady_state_response

    frequencies = parse_frequencies(args.frequencies, args.range, args.spacing)
    config = parameters(args)
    simulation = dict(config["simulation"])
    amplitude = args.amplitude
    if amplitude is None:
        amplitude = config["excitation"].get("amplitude", EXCITATION["amplitude"])
    plot = figure_path(args)
    beside = []  # the curve as data beside its figure: NetCDF, CSV and MATLAB
    if plot is not None:
        check_output(args, "--plot", plot, suffixes=PLOT_SUFFIXES)
        beside = [Path(plot).with_suffix(suffix) for suffix in CURVE_SUFFIXES]
        for path in beside:
            check_output(args, "--plot", path, suffixes=RESPONSE_SUFFIXES)
    if args.out:
        check_output(args, "--out", args.out, suffixes=RESPONSE_SUFFIXES)
    options = {}
    if args.dt is not None:
        options["dt"] = args.dt
    elif args.tolerance is not None:
        options["tolerance"] = args.tolerance
    elif "dt" in simulation:
        options["dt"] = simulation["dt"]
    if args.solver or "solver" in simulation:
        options["solver"] = args.solver or simulation["solver"]
    for flag, name in (("periodic_tolerance", "periodic_tolerance"),
                       ("max_periods", "max_periods"), ("max_time", "max_time"),
                       ("harmonics", "harmonics"),
                       ("friction_velocity", "friction_velocity"), ("workers", "workers")):
        value = getattr(args, flag)
        if value is not None:
            options[name] = value
    response = steady_state_response(
        frequencies, amplitude, config["isolator"], config["controller"],
        direction=args.direction, harmonic_balance=not args.no_harmonic_balance,
        compare_chirp=args.compare_chirp, progress=not args.quiet and not args.json, **options)
    files = {}
    if args.out:
        response.save(args.out)
        files["out"] = args.out
    if plot is not None:
        import matplotlib.pyplot as plt

        plt.close(response.plot(path=plot, frequency_scale=args.frequency_axis))
        files["plot"] = plot
        for path in beside:
            response.save(path)
            files[f"curve{path.suffix}"] = str(path)
    text = response.summary() + "".join(f"\n  wrote            {p}" for p in files.values())
    if args.json:
        for note in response.notes:
            print(f"qzs: note: {note}", file=sys.stderr)
    emit(args, text, response.to_records())
    return 0
