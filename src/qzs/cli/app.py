"""``qzs app``: the interactive tuning page in the browser (docs/app.md).

It parses and delegates to :func:`qzs.app.server.serve`; it computes nothing.
"""
import argparse

from qzs.cli.common import add_spring_option

__all__ = ["add_parser", "run"]


def _port(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer in [0, 65535], got {text!r}") \
            from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be an integer in [0, 65535], got {value}")
    return value


def add_parser(subparsers):
    """Add ``app`` to an ``argparse`` sub-parser collection.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``app`` parser.
    """
    parser = subparsers.add_parser(
        "app", help="interactive tuning page in the browser (needs qzs[app])",
        description="Serve a local web page with sliders for the friction, spring, mass and "
                    "controller parameters and the excitation, redrawing the transmissibility "
                    "(trusted bins, the linear model dashed), the payload's response to a sine, "
                    "the stroke against the stops, the motor force against its limit and the "
                    "locked share within a second of a slider's release. Pin curves, reset to "
                    "the paper's defaults, export the parameters as a TOML config for "
                    "`qzs simulate --config` and the figure as PNG (browser downloads: the "
                    "server writes no file). Runs until Ctrl-C (`qzs docs app`).")
    parser.add_argument("--port", type=_port, metavar="N",
                        help="port to listen on (default 5006 if free, else a free one; "
                             "0: any free port)")
    parser.add_argument("--host", default="127.0.0.1", metavar="ADDRESS",
                        help="address to bind (default 127.0.0.1: this machine only; another "
                             "address is served with a warning: the page has no login)")
    parser.add_argument("--no-browser", action="store_true",
                        help="do not open the page in the default browser")
    add_spring_option(parser, config=False)
    return parser


def run(args):
    """Run ``qzs app`` from parsed arguments until Ctrl-C (exit code 130).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs app`` arguments.

    Returns
    -------
    int
        The exit code; the server runs until Ctrl-C, which :func:`qzs.cli.main` turns
        into 130.
    """
    from qzs.app.server import serve

    options = {}
    if args.spring:  # the page's sliders are then this law's spring.* parameters
        from qzs.iotools.config import load_spring

        options["spring"] = load_spring(args.spring)
    return serve(port=args.port, host=args.host, open_browser=not args.no_browser, **options)
