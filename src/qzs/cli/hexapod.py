"""``qzs hexapod``: the six-axis platform of six isolator legs (docs/hexapod.md)."""
from qzs._validation import positive_real
from qzs.cli.common import (EPILOG, add_frequency_axis_option, add_output_options, add_set_option,
                             check_output, emit, figure_path, integer_at_least, settings)
from qzs.defaults import ACCURACY, AXES, HEXAPOD
from qzs.errors import ParameterError
from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT

__all__ = ["add_parser", "run_linear", "run_simulate", "run_transmissibility",
           "run_study"]

#: What every subcommand takes without --config or --cubic (one default for all of them).
DEFAULT_SETUP = (f"Without --config or --cubic: the shipped {SHIPPED_DEFAULT} platform (cube "
                 f"edge {HEXAPOD['cube_edge']:g} m, Kp = 2000 N/m, carrying what its six "
                 "MagSprings hold; `qzs docs hexapod` §8).")
#: ``--frame`` choices and the name the analysis takes.
FRAMES = {"center-of-mass": "center_of_mass", "origin": "origin", "cube-center": "cube_center"}


def _add_setup_options(parser):
    parser.add_argument("--config", metavar="FILE.toml",
                        help="hexapod file, or a shipped one's name: [geometry], [platform], "
                             "[leg], [controller], [excitation.<axis>], [simulation] (layout: "
                             "`qzs docs hexapod` §8; default the shipped "
                             f"{SHIPPED_DEFAULT})")
    parser.add_argument("--cubic", action="store_true",
                        help="a cubic configuration without a file (with --cube-edge; the "
                             "legs' default loops, Kp = 50 N/m)")
    parser.add_argument("--cube-edge", metavar="M", type=float,
                        help=f"edge of the cube [m] (with --cubic; default {HEXAPOD['cube_edge']:g})")
    parser.add_argument("--cube-center-height", metavar="M", type=float,
                        help="height of the cube's centre above the base [m] (with --cubic; "
                             "default: the legs' lower ends on the base plane, edge/(2*sqrt(3)))")
    parser.add_argument("--centralised", action="store_true",
                        help="centralised control: the PI and damping loops on the platform's "
                             "six axes at the top frame origin, with the legs' stiffness on "
                             "each axis (`qzs docs hexapod` §9.5); a [cartesian] table in the "
                             "file sets other gains")
    add_set_option(parser)


def _add_step_options(parser):
    step = parser.add_mutually_exclusive_group()
    step.add_argument("--dt", type=float, metavar="S",
                      help="a literal integration step [s] for every run (default: each "
                           "run's step chosen for --tolerance, else the file's dt)")
    step.add_argument("--tolerance", type=float, metavar="DB",
                      help="tolerance of each run's step on its column of the matrix [dB] (default "
                           f"{ACCURACY['tolerance_db']:g}, `qzs docs hexapod` §10.3)")


def add_parser(subparsers):
    """Add ``hexapod`` and its subcommands to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``hexapod`` parser.
    """
    hexapod = subparsers.add_parser(
        "hexapod", help="six isolator legs in a Stewart platform",
        description="The six-axis platform of the paper's future work: six semi-active QZS "
                    "legs between a base and a rigid top (`qzs docs hexapod`).")
    sub = hexapod.add_subparsers(dest="hexapod_command", required=True)
    linear = sub.add_parser(
        "linear", help="stiffness matrix and modes at the operating point",
        description="Linearise the platform about its home pose (every leg slipping, motors "
                    "unsaturated) and print the 6x6 stiffness matrix and the modes. "
                    + DEFAULT_SETUP)
    _add_setup_options(linear)
    linear.add_argument("--leg-stiffness", metavar="N_PER_M", type=float,
                        help="replace every leg's axial stiffness [N/m] (a purely linear "
                             "analysis: spring tangent + Kp otherwise)")
    linear.add_argument("--frame", choices=tuple(FRAMES), default="center-of-mass",
                        help="where the matrices are expressed (default: the payload's centre "
                             "of mass; cube-center: a cubic geometry's cube centre)")
    linear.add_argument("--no-preload", action="store_true",
                        help="leave out the geometric stiffness of the static leg forces")
    add_frequency_axis_option(linear)
    add_output_options(linear, plot=dict(help="the 6x6 transmissibility of the linear model "
                                              "(0.05-50 Hz)"))
    linear.set_defaults(handler=run_linear)
    simulate = sub.add_parser(
        "simulate", help="simulate the platform: stick-slip on every leg",
        description="Simulate the six-leg platform (exact stick-slip on every leg, stops, "
                    "per-leg PI and damping, `qzs docs hexapod` §9) under the base motion "
                    "of the file's [excitation.<axis>] tables or of --axis/--excitation, and "
                    "print a "
                    "summary per leg: stroke used, stop contacts, time locked, motor RMS. "
                    + DEFAULT_SETUP)
    _add_setup_options(simulate)
    simulate.add_argument("--controller", metavar="FILE.toml",
                          help="controller file for every leg: a [controller] table with its "
                               "blocks' tables ([controller.compensation], [controller.dither], "
                               "[controller.linear]), as `qzs simulate --controller`; replaces "
                               "the hexapod file's [controller] and [legs.N.controller]")
    simulate.add_argument("--leg-controller", metavar="N=FILE.toml", action="append",
                          default=[],
                          help="leg N's own controller file (N from 1 to 6; repeatable, each "
                               "leg once); replaces what the hexapod file or --controller "
                               "gives that leg (`qzs docs hexapod` §9.5a)")
    simulate.add_argument("--spring", metavar="FILE.toml",
                          help="spring file for every leg: a [spring] table (law = \"tanh\", "
                               "\"oblique\", \"polynomial\" or \"table\" and its parameters), "
                               "as `qzs simulate --spring`")
    simulate.add_argument("--leg-spring", metavar="N=FILE.toml", action="append", default=[],
                          help="leg N's own spring file (N from 1 to 6; repeatable, each leg "
                               "once); replaces what --spring gives that leg")
    simulate.add_argument("--axis", choices=AXES,
                          help="the base axis --excitation drives (replaces the file's table "
                               "for that axis); rotations in [rad]")
    simulate.add_argument("--excitation", choices=("chirp", "sine", "random"),
                          help="base motion along --axis (default chirp)")
    simulate.add_argument("--amplitude", type=float, metavar="M",
                          help="amplitude [m] (or [rad] for a rotation axis)")
    simulate.add_argument("--f0", type=float, metavar="HZ", help="chirp start / random band low [Hz]")
    simulate.add_argument("--f1", type=float, metavar="HZ", help="chirp end / random band high [Hz]")
    simulate.add_argument("--frequency", type=float, metavar="HZ", help="sine frequency [Hz]")
    simulate.add_argument("--excitation-duration", type=float, metavar="S",
                          help="length of the chirp or random excitation [s]")
    simulate.add_argument("--duration", type=float, metavar="S", help="simulated time [s]")
    step = simulate.add_mutually_exclusive_group()
    step.add_argument("--dt", type=float, metavar="S",
                      help="a literal integration step [s] (default: the step chosen for "
                           "the tolerance, halving down to the file's dt, `qzs docs "
                           "hexapod` §10.3)")
    step.add_argument("--tolerance", type=float, metavar="DB",
                      help="tolerance on the driven axis's transmissibility column [dB] (the "
                           f"default measure for a chirp along one axis; default "
                           f"{ACCURACY['tolerance_db']:g})")
    step.add_argument("--tolerance-state", type=float, metavar="M",
                      help="tolerance on the platform's pose [m], rotations as arcs at the "
                           "platform's size (the default measure for other base motions; "
                           f"default {ACCURACY['tolerance_state']:g})")
    simulate.add_argument("--sample-rate", type=float, metavar="HZ", help="output rate [Hz]")
    simulate.add_argument("--solver", choices=("ode3", "rk4", "euler"),
                          help="integrator (default the file's, else ode3)")
    add_output_options(simulate, out=dict(metavar="FILE", help="write the run as NetCDF (.nc, "
                                                              "CF-1.10) or MATLAB (.mat)"),
                       plot=dict(help="figure of the run"))
    simulate.set_defaults(handler=run_simulate)
    matrix = sub.add_parser(
        "transmissibility", help="the simulated 6x6 transmissibility: one chirp per axis",
        description="Simulate one chirp per excited base axis (in parallel processes) and "
                    "estimate the 6x6 transmissibility matrix with the single axis's Welch "
                    "estimator and its trusted bins (`qzs docs hexapod` §10); write the 6x6 "
                    "grid (linear model dashed) and the matrix as NetCDF to --out and print a "
                    "summary. " + DEFAULT_SETUP)
    _add_setup_options(matrix)
    matrix.add_argument("--axes", metavar="AXES", default=",".join(AXES),
                        help="comma-separated base axes to excite, one run each (default "
                             f"all six: {','.join(AXES)})")
    matrix.add_argument("--amplitude", metavar="AMPLITUDE",
                        help="chirp amplitude: one number for every excited axis (all "
                             "translations [m] or all rotations [rad]) or per axis, e.g. "
                             "z=0.001,rx=0.005 (default 0.002 m, 0.01 rad)")
    matrix.add_argument("--f0", type=float, metavar="HZ", help="chirp start [Hz] (default 0)")
    matrix.add_argument("--f1", type=float, metavar="HZ", help="chirp end [Hz] (default 20)")
    matrix.add_argument("--duration", type=float, metavar="S",
                        help="chirp length and run time [s] (default 200)")
    _add_step_options(matrix)
    matrix.add_argument("--sample-rate", type=float, metavar="HZ",
                        help="output rate [Hz] (default the file's, else 1000)")
    matrix.add_argument("--workers", type=integer_at_least(1), metavar="N",
                        help="parallel runs (default: all cores)")
    add_frequency_axis_option(matrix)
    add_output_options(matrix, out=dict(metavar="DIR", default="results/hexapod_transmissibility",
                                        unnamed="replace", help="folder for transmissibility.png and "
                                             "transmissibility.nc (default "
                                             "results/hexapod_transmissibility)"))
    matrix.set_defaults(handler=run_transmissibility)
    study = sub.add_parser(
        "study", help="the shipped study: paper legs, chirps in z and x, with and without PI",
        description="Six paper legs carrying what their MagSprings hold (paper_legs_cubic), "
                    "the 6x6 transmissibility from chirps in z and in x for three loops: PI, "
                    "P only (Ki = 0) and no position loop (Kp = Ki = 0, statically unstable "
                    "here); writes report.md, metrics.csv/json, figures and the matrices.")
    study.add_argument("--quick", action="store_true",
                       help="60 s chirps instead of 400 s (well under a minute)")
    _add_step_options(study)
    study.add_argument("--workers", type=integer_at_least(1), metavar="N",
                       help="parallel runs per case (default: all cores)")
    add_frequency_axis_option(study)
    add_output_options(study, out=dict(metavar="DIR", default="results/hexapod_study",
                                       unnamed="replace", help="output folder (default results/hexapod_study)"))
    study.set_defaults(handler=run_study)
    for command in sub.choices.values():
        command.epilog = EPILOG
    return hexapod


def _setup(args):
    """The set-up the options describe (delegates to :mod:`qzs.workflows.hexapod.setups`): the
    --config file, else a --cubic configuration, else the shipped default
    (:data:`DEFAULT_SETUP`, the same for every subcommand)."""
    from qzs.workflows.hexapod.setups import centralised

    setup = _described_setup(args)
    return centralised(setup) if args.centralised else setup


def _described_setup(args):
    from qzs.model.hexapod import cubic_geometry
    from qzs.workflows.hexapod.setups import (default_cube_center_height, hexapod_setup,
                                              load_hexapod)

    overrides = settings(args.set)
    controllers = _controllers(args)
    cube_options = args.cube_edge is not None or args.cube_center_height is not None
    if args.config and (args.cubic or cube_options):
        raise ParameterError("give either --config or --cubic (with --cube-edge), not both.")
    if cube_options and not args.cubic:
        raise ParameterError("--cube-edge and --cube-center-height describe a cubic "
                             "configuration: add --cubic.")
    if args.config:
        return load_hexapod(args.config, overrides, **controllers)
    if args.cubic:
        edge = HEXAPOD["cube_edge"] if args.cube_edge is None else args.cube_edge
        positive_real("--cube-edge", edge, fix="a length in m")
        height = (default_cube_center_height(edge) if args.cube_center_height is None
                  else args.cube_center_height)
        geometry = cubic_geometry(cube_edge=edge, cube_center_height=height)
        controllers.pop("names")
        return hexapod_setup(geometry=geometry, settings=overrides, kind="cubic", **controllers)
    return load_hexapod(SHIPPED_DEFAULT, overrides, **controllers)


def _controllers(args):
    """``--leg-controller`` and ``--controller`` (``simulate``'s) as ``load_hexapod``'s
    ``legs``, ``controller`` and ``names``: every leg number checked before any file is
    read."""
    from qzs.iotools.config import load_controller
    from qzs.workflows.hexapod.setups import read_leg_controllers

    legs, names = read_leg_controllers(getattr(args, "leg_controller", None) or ())
    path = getattr(args, "controller", None)
    if path:
        names["controller"] = f"--controller {path}"
    return {"controller": load_controller(path) if path else None, "legs": legs,
            "names": names}


def _with_springs(args, setup):
    """``--leg-spring`` and ``--spring`` (``simulate``'s) on ``setup``'s legs: every leg
    number checked before any file is read."""
    from qzs.iotools.config import load_spring
    from qzs.workflows.hexapod.setups import read_leg_springs, with_spring_laws

    legs, _ = read_leg_springs(args.leg_spring)
    spring = load_spring(args.spring) if args.spring else None
    if spring is None and not legs:
        return setup
    return with_spring_laws(setup, spring, legs)


def run_linear(args):
    """Run ``qzs hexapod linear`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        0.
    """
    from qzs.workflows.hexapod.setups import linear_record, linear_text

    if args.leg_stiffness is not None:
        positive_real("--leg-stiffness", args.leg_stiffness, fix="a stiffness in N/m")
    plot = figure_path(args)
    if plot is not None:
        check_output(args, "--plot", plot, suffixes=(".png", ".svg", ".pdf"))
    setup = _setup(args)
    model, record = linear_record(setup, leg_stiffness=args.leg_stiffness,
                                  frame=FRAMES[args.frame], include_preload=not args.no_preload)
    text = linear_text(setup, model, record)
    if plot is not None:
        from qzs.workflows.hexapod.setups import plot_linear_transmissibility

        record["plot"] = str(plot_linear_transmissibility(
            setup, model, plot, frequency_scale=args.frequency_axis))
        text += f"\n  wrote {plot}"
    emit(args, text, record)
    return 0


_EXCITATION_OPTIONS = ("amplitude", "f0", "f1", "frequency")


def run_simulate(args):
    """Run ``qzs hexapod simulate`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        0.
    """
    from qzs.engine.hexapod.result import HEXAPOD_SUFFIXES
    from qzs.workflows.hexapod.setups import simulate_setup

    given = [name for name in (*_EXCITATION_OPTIONS, "excitation", "excitation_duration")
             if getattr(args, name) is not None]
    if given and args.axis is None:
        raise ParameterError(f"--{given[0].replace('_', '-')} describes the base motion of "
                             "one axis: add --axis (x, y, z, rx, ry or rz).")
    if args.out:
        check_output(args, "--out", args.out, suffixes=HEXAPOD_SUFFIXES)
    plot = figure_path(args)
    if plot is not None:
        check_output(args, "--plot", plot, suffixes=(".png", ".svg", ".pdf"))
    setup = _with_springs(args, _setup(args))
    excitation = None
    if args.axis is not None:
        options = {"kind": args.excitation or "chirp"}
        options.update({name: getattr(args, name) for name in _EXCITATION_OPTIONS
                        if getattr(args, name) is not None})
        if args.excitation_duration is not None:
            options["duration"] = args.excitation_duration
        excitation = {args.axis: options}
    result = simulate_setup(setup, excitation=excitation, duration=args.duration, dt=args.dt,
                            tolerance=args.tolerance, tolerance_state=args.tolerance_state,
                            sample_rate=args.sample_rate, solver=args.solver,
                            progress=not args.quiet and not args.json, out=args.out or None,
                            interruptible=True, argument="--out",
                            names={**{name: f"--{name}" for name in _EXCITATION_OPTIONS},
                                   "duration": "--excitation-duration"})
    text = result.summary()
    record = {"summary": text, "run": result.run, "source": setup.source,
              "step": {key: value for key, value in result.run.items()
                       if key in ("dt", "step") or key.startswith("step_")}}
    if args.out:
        text += f"\n  wrote            {args.out}"
        record["out"] = args.out
    if plot is not None:
        import matplotlib.pyplot as plt

        plt.close(result.plot(path=plot))
        text += f"\n  wrote            {plot}"
        record["plot"] = plot
    emit(args, text, record)
    return 0


def _amplitude(text):
    """``--amplitude``: one number, or ``AXIS=VALUE`` pairs separated by commas."""
    if text is None:
        return None
    if "=" not in text:
        try:
            return float(text)
        except ValueError:
            raise ParameterError(f"--amplitude must be a number or AXIS=VALUE pairs (e.g. "
                                 f"z=0.001,rx=0.005), got {text!r}.") from None
    values = {}
    for pair in text.split(","):
        axis, _, value = pair.partition("=")
        try:
            values[axis.strip()] = float(value)
        except ValueError:
            raise ParameterError(f"--amplitude: {pair!r} is not AXIS=VALUE with a number "
                                 "(e.g. z=0.001).") from None
    return values


def run_transmissibility(args):
    """Run ``qzs hexapod transmissibility`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        0.
    """
    from pathlib import Path

    from qzs.workflows.hexapod.transmissibility import (CHIRP, hexapod_transmissibility,
                                                        transmissibility_record)

    check_output(args, "--out", args.out, suffixes=None, directory=True)
    setup = _setup(args)
    options = {name: getattr(args, name) for name in ("f0", "f1", "duration")
               if getattr(args, name) is not None}
    result = hexapod_transmissibility(
        setup, axes=args.axes, amplitude=_amplitude(args.amplitude),
        **{**dict(CHIRP), **options}, dt=args.dt, tolerance=args.tolerance,
        sample_rate=args.sample_rate,
        workers=args.workers, progress=not args.quiet and not args.json)
    folder = Path(args.out)
    figure = folder / "transmissibility.png"
    data = folder / "transmissibility.nc"
    import matplotlib.pyplot as plt

    plt.close(result.plot(path=figure, frequency_scale=args.frequency_axis))
    result.save(data)
    text = result.summary() + f"\n  wrote {figure} and {data}"
    record = {**transmissibility_record(result), "figure": str(figure), "netcdf": str(data)}
    emit(args, text, record)
    return 0


def run_study(args):
    """Run ``qzs hexapod study`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.

    Returns
    -------
    int
        0.
    """
    from qzs.workflows.hexapod.study import run_hexapod_study, study_steps

    check_output(args, "--out", args.out, suffixes=None, directory=True)
    result = run_hexapod_study(args.out, quick=args.quick, dt=args.dt,
                               tolerance=args.tolerance, workers=args.workers,
                               progress=not args.quiet and not args.json,
                               frequency_scale=args.frequency_axis)
    record = {"quick": result.quick, "wall_seconds": result.wall_seconds,
              "steps": study_steps(result),
              "rows": list(result.rows), "findings": list(result.findings),
              "files": {name: str(path) for name, path in result.files.items()}}
    emit(args, result.summary(), record)
    return 0
