"""``qzs design``: PI and damping gains from the isolator and its disturbance (docs/design.md)."""
import math

from qzs.cli.common import (EPILOG, add_frequency_axis_option, add_output_options,
                             add_set_option, check_output, emit, integer_at_least, parameters)
from qzs.errors import ParameterError

__all__ = ["add_parser", "run", "parse_pair", "parse_list"]

#: Default output folder of ``qzs design``.
DEFAULT_FOLDER = "results/design"


def parse_pair(option, text, unit):
    """``LOW,HIGH`` as two floats, or a :class:`ParameterError` naming the option.

    Parameters
    ----------
    option : str
        The option's name (``--stiction-range``), for the message.
    text : str
        What was typed.
    unit : str
        The unit of both numbers, for the message.

    Returns
    -------
    tuple of float
        ``(low, high)``.
    """
    parts = [p.strip() for p in str(text).split(",")]
    try:
        low, high = (float(p) for p in parts)
    except ValueError:
        raise ParameterError(f"{option} expects LOW,HIGH in {unit} (two numbers and a comma, "
                             f"e.g. 5,15), got {text!r}.") from None
    if not (math.isfinite(low) and math.isfinite(high) and low <= high):
        raise ParameterError(f"{option} expects finite LOW <= HIGH in {unit}, got {text!r}.")
    return low, high


def parse_list(option, text, unit):
    """``A,B,...`` as floats (empty text: none), or a :class:`ParameterError` naming the option.

    Parameters
    ----------
    option : str
        The option's name, for the message.
    text : str
        What was typed.
    unit : str
        The unit of the numbers, for the message.

    Returns
    -------
    tuple of float
    """
    if not str(text).strip():
        return ()
    try:
        values = tuple(float(p) for p in str(text).split(","))
    except ValueError:
        raise ParameterError(f"{option} expects numbers in {unit} separated by commas (e.g. "
                             f"-2,2), got {text!r}.") from None
    if not all(math.isfinite(v) for v in values):
        raise ParameterError(f"{option} expects finite numbers in {unit}, got {text!r}.")
    return values


def add_parser(subparsers):
    """Add ``design`` to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``design`` parser.
    """
    cmd = subparsers.add_parser(
        "design", help="PI and damping gains by simulation, with the evidence",
        description="Find the smallest PI gains (Ki/Kp of the given controller kept) that keep "
                    "the payload in the spring's constant-force band and off the stops under "
                    "the base motion, payload force steps and at rest, over ranges of stiction "
                    "and mass; whether the PI loop hunts (describing functions and simulation); "
                    "the damping gain that minimises a transmissibility cost; the sampled "
                    "loop's margins and the rate it needs; why active damping did not help "
                    "much in the paper; the static design. Writes report.html, design.json "
                    "and figures (`qzs docs design`).",
        epilog="The base motion is the config's [excitation] (default the paper's 10 mm, "
               "0-20 Hz, 2000 s chirp; --quick: the same sweep in 200 s, the ranges' ends "
               "only, a coarser search: about a minute). The output folder is checked before "
               "any simulation. " + EPILOG)
    cmd.add_argument("--config", metavar="FILE.toml",
                     help="run configuration: [isolator], [controller], [excitation] "
                          "(see `qzs params --toml`)")
    add_set_option(cmd)
    cmd.add_argument("--stiction-range", metavar="LOW,HIGH",
                     help="stiction forces [N] the design must cover (default: 0.5 and 1.5 "
                          "times the isolator's, 5,15)")
    cmd.add_argument("--mass-range", metavar="LOW,HIGH",
                     help="moving masses [kg] (default: the isolator's +-0.2 kg, 6.2,6.6)")
    cmd.add_argument("--force-steps", metavar="DF,...", default="-2,2",
                     help="payload force steps [N], upward positive, applied at t = 0 under the "
                          "base motion (default -2,2: about the weight deficit the integral "
                          "carries; '' for none)")
    cmd.add_argument("--band", metavar="LOW,HIGH", default="1,20",
                     help="band of the transmissibility cost [Hz] (default 1,20)")
    cmd.add_argument("--cost", choices=("rms", "peak"), default="rms",
                     help="cost the damping gain minimises: RMS of T over the band's trusted "
                          "bins, or its peak (default rms)")
    cmd.add_argument("--controller-rate", metavar="HZ", type=float,
                     help="controller rate with zero-order hold [Hz]; 0 continuous (default: "
                          "the controller's controller_rate, 0); it must share the integration "
                          "step with the runs' output rate: a divisor or whole multiple of it")
    cmd.add_argument("--delay", metavar="S", type=float, default=0.0,
                     help="delay from sampling to the motor force [s], for the margins and the "
                          "linear delay experiment (the simulator has none; default 0)")
    cmd.add_argument("--damping-max", metavar="N_S_PER_M", type=float, default=1000.0,
                     help="largest damping gain tried [N*s/m] (default 1000, ten times the "
                          "guide's viscous friction)")
    cmd.add_argument("--quick", action="store_true",
                     help="short runs and a coarse search (about a minute)")
    cmd.add_argument("--workers", metavar="N", type=integer_at_least(1),
                     help="threads (default: all cores)")
    add_frequency_axis_option(cmd)
    add_output_options(cmd, out=dict(metavar="FOLDER", default=DEFAULT_FOLDER,
                                     unnamed="replace",
                                     help=f"output folder (default {DEFAULT_FOLDER})"))
    return cmd


def run(args):
    """Run ``qzs design`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs design`` arguments.

    Returns
    -------
    int
        0.
    """
    from qzs.model.excitation import build_excitation
    from qzs.workflows.design import design_controller
    from qzs.workflows.design.result import write_design

    config = parameters(args)
    stiction = (None if args.stiction_range is None
                else parse_pair("--stiction-range", args.stiction_range, "N"))
    mass = None if args.mass_range is None else parse_pair("--mass-range", args.mass_range, "kg")
    band = parse_pair("--band", args.band, "Hz")
    steps = parse_list("--force-steps", args.force_steps, "N")
    excitation = None
    if config["excitation"]:
        options = dict(config["excitation"])
        excitation = build_excitation(options.pop("kind", "chirp"), options)
    folder = check_output(args, "--out", args.out, suffixes=None, directory=True,
                          estimated_bytes=5e6)
    result = design_controller(
        config["isolator"], config["controller"], excitation=excitation,
        stiction_range=stiction, mass_range=mass, force_steps=steps, band=band, cost=args.cost,
        controller_rate=args.controller_rate, delay=args.delay, quick=args.quick,
        damping_gain_max=args.damping_max, workers=args.workers,
        progress=not args.quiet and not args.json)
    written = write_design(result, folder, frequency_scale=args.frequency_axis,
                           progress=not args.quiet and not args.json)
    record = result.to_dict()
    record["outputs"] = {name: str(path) for name, path in written.items()}
    emit(args, result.summary() + f"\n  wrote            {written['report']}", record)
    return 0
