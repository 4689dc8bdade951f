"""``qzs docs``: the model and workflow pages shipped inside the package, in the terminal."""
from qzs.cli.common import EPILOG
from qzs.errors import ParameterError
from qzs.iotools.docs import read_topic, topic_names, topics

__all__ = ["add_parser", "run"]


def add_parser(subparsers):
    """Add ``docs`` to an ``argparse`` sub-parser collection; returns the parser.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.

    Returns
    -------
    argparse.ArgumentParser
        The ``docs`` parser.
    """
    parser = subparsers.add_parser(
        "docs", help="show the model and workflow documentation shipped with qzs",
        description="Without a topic, list the documentation topics; with one, print its page "
                    "(Markdown); with a section number as well, print only that section. "
                    "Help texts cite these as \"`qzs docs model` §7\".",
        epilog="Examples: `qzs docs model 7` (or §7, or --section 7), `qzs docs simulate`, "
               "`qzs docs hexapod 9.5 | less`. " + EPILOG)
    topic = parser.add_argument("topic", nargs="?", metavar="TOPIC",
                                help="a topic of the list `qzs docs` prints (model, hexapod, "
                                     "command-line, ...)")
    topic.completion_words = topic_names()  # for `qzs completion` (qzs.cli.completion)
    parser.add_argument("section", nargs="?", metavar="SECTION",
                        help="a section number of the page (7, §7, 9.5)")
    parser.add_argument("--section", dest="section_option", metavar="N",
                        help="the same as SECTION")
    return parser


def run(args):
    """Run ``qzs docs`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs docs`` arguments.

    Returns
    -------
    int
        The exit code, 0.

    Raises
    ------
    ParameterError
        An unknown topic or section (exit code 2), or a section without a topic.
    """
    section = args.section_option or args.section
    if args.section and args.section_option and args.section != args.section_option:
        raise ParameterError(f"--section {args.section_option}: the section is given twice "
                             f"(also {args.section!r}); give it once.")
    if args.topic is None:
        if section is not None:
            raise ParameterError(f"--section {section}: name the topic too, e.g. "
                                 f"`qzs docs model {section}`.")
        listed = topics()
        width = max(map(len, listed))
        print("Documentation topics (`qzs docs TOPIC [SECTION]`):")
        for name, title in listed.items():
            print(f"  {name:<{width}}  {title}")
        return 0
    print(read_topic(args.topic, section), end="")
    return 0
