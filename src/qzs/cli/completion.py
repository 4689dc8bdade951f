"""``qzs completion bash|zsh``: a shell completion script generated from the parser.

The script is written from the ``qzs`` parser itself (:func:`qzs.cli.build_parser`), so it
knows every subcommand, option and choice of the qzs that printed it and needs nothing at
completion time (no Python start per TAB, no new dependency). It completes subcommands
(nested ones such as ``qzs hexapod simulate`` too), a command's options, an option's choices
(``--solver ode3|rk4|euler``), the words of a positional argument that lists them (the
topics of ``qzs docs``) and, for every other value, file names::

    eval "$(qzs completion bash)"          # in ~/.bashrc
    eval "$(qzs completion zsh)"           # in ~/.zshrc, after compinit
"""
import argparse

from qzs._version import __version__
from qzs.cli.common import EPILOG

__all__ = ["add_parser", "run", "command_tree", "bash_script", "zsh_script", "SHELLS"]

#: What an action's ``completion_words`` attribute may name besides ``choices``: the words a
#: positional argument completes to (set by the subcommand's module, e.g. ``qzs docs``).
WORDS_ATTRIBUTE = "completion_words"


def add_parser(subparsers, root):
    """Add ``completion`` to an ``argparse`` sub-parser collection; returns the parser.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        What ``ArgumentParser.add_subparsers`` returned.
    root : argparse.ArgumentParser
        The ``qzs`` parser itself, whose script the command prints (complete by the time
        the command runs).

    Returns
    -------
    argparse.ArgumentParser
        The ``completion`` parser.
    """
    parser = subparsers.add_parser(
        "completion", help="print a bash or zsh completion script for qzs",
        description="Print a completion script for the given shell, generated from this "
                    "qzs's parser: subcommands, options, their choices and file names.",
        epilog='Load it once per shell: eval "$(qzs completion bash)" in ~/.bashrc, or '
               'eval "$(qzs completion zsh)" in ~/.zshrc after compinit; or save it as a '
               "file: qzs completion bash > ~/.local/share/bash-completion/completions/qzs. "
               + EPILOG)
    parser.add_argument("shell", choices=SHELLS, help="the shell: bash or zsh")
    parser.set_defaults(root_parser=root)
    return parser


def run(args):
    """Run ``qzs completion`` from parsed arguments; returns the exit code.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed ``qzs completion`` arguments (``root_parser``: the ``qzs`` parser).

    Returns
    -------
    int
        The exit code, 0.
    """
    print(SHELLS[args.shell](command_tree(args.root_parser)), end="")
    return 0


def command_tree(parser, path=""):
    """Every command of a parser, with its subcommands, options and their values.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The top-level parser (or a subcommand's).
    path : str
        The command words before this parser's own (``"hexapod"``); ``""`` at the top.

    Returns
    -------
    dict
        Command path (``""``, ``"simulate"``, ``"hexapod simulate"``) -> a dict with
        ``commands`` (name -> one-line help), ``options`` (option string -> one-line help),
        ``values`` (option string -> its choices, empty for any value: a file name) and
        ``words`` (what a positional argument completes to besides file names).
    """
    entry = {"commands": {}, "options": {}, "values": {}, "words": []}
    tree = {path: entry}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
            for name, sub in action.choices.items():
                entry["commands"][name] = _line(helps.get(name, ""))
                tree.update(command_tree(sub, f"{path} {name}".strip()))
        elif action.option_strings:
            for option in action.option_strings:
                entry["options"][option] = _line(action.help)
                if action.nargs != 0:
                    entry["values"][option] = [str(choice) for choice in action.choices or ()]
        else:
            words = action.choices or getattr(action, WORDS_ATTRIBUTE, None) or ()
            entry["words"] += [str(word) for word in words if str(word) not in entry["words"]]
    return tree


def _line(text):
    """The first sentence of a help text, ``%%`` unescaped, for a completion menu."""
    text = " ".join(str(text or "").replace("%%", "%").split())
    return text.split(". ")[0].rstrip(".")


def _quote(word):
    """``word`` in single quotes, for both shells."""
    return "'" + str(word).replace("'", "'\\''") + "'"


def _lookups(commands, options):
    """The shell functions ``_qzs_commands`` and ``_qzs_options``: a command path -> what
    the script does for it (``(path, shell code)`` pairs), the same in bash and zsh."""
    return (f"_qzs_commands() {{\n    case \"$1\" in\n{_cases(commands)}\n    esac\n}}\n"
            f"_qzs_options() {{\n    case \"$1\" in\n{_cases(options)}\n    esac\n}}\n")


def _cases(pairs, indent="        "):
    """``case`` arms ``'key') body;;`` of ``(key, body)`` pairs, one per line."""
    return "\n".join(f"{indent}{_quote(key)}) {body};;" for key, body in pairs)


def _common_functions(tree):
    """The shell functions both scripts share: the command path, and what it takes."""
    subcommand = [(f"{path}|{name}", f"echo {_quote(f'{path} {name}'.strip())}")
                  for path, entry in tree.items() for name in entry["commands"]]
    takes_value = [(f"{path}|{option}", "return 0") for path, entry in tree.items()
                   for option in entry["values"]]
    choices = [(f"{path}|{option}", f"echo {_quote(' '.join(values))}")
               for path, entry in tree.items() for option, values in entry["values"].items()
               if values]
    words = [(path, f"echo {_quote(' '.join(entry['words']))}")
             for path, entry in tree.items() if entry["words"]]
    return f"""\
_qzs_subcommand() {{  # $1 the command path, $2 a word: the longer path, if it is a subcommand
    case "$1|$2" in
{_cases(subcommand)}
    esac
}}
_qzs_takes_value() {{  # $1 the command path, $2 an option: does it take a value?
    case "$1|$2" in
{_cases(takes_value)}
    esac
    return 1
}}
_qzs_choices() {{  # $1 the command path, $2 an option: its choices (none: any value, a file)
    case "$1|$2" in
{_cases(choices)}
    esac
}}
_qzs_words() {{  # $1 the command path: what its positional arguments complete to
    case "$1" in
{_cases(words)}
    esac
}}
_qzs_path() {{  # the command path of the words before the cursor: "", "hexapod simulate"
    local command_path="" word next skip=0
    for word in "$@"; do
        if [ "$skip" = 1 ]; then skip=0; continue; fi
        case "$word" in
            --*=*) continue;;
            -*) _qzs_takes_value "$command_path" "$word" && skip=1; continue;;
        esac
        next="$(_qzs_subcommand "$command_path" "$word")"
        [ -n "$next" ] && command_path="$next"
    done
    echo "$command_path"
}}
"""


def bash_script(tree):
    """The bash completion script of a command tree (:func:`command_tree`).

    Parameters
    ----------
    tree : dict
        What :func:`command_tree` returned.

    Returns
    -------
    str
        A script that defines ``_qzs`` and registers it with ``complete -F _qzs qzs``.
    """
    commands = [(path, f"echo {_quote(' '.join(entry['commands']))}")
                for path, entry in tree.items() if entry["commands"]]
    options = [(path, f"echo {_quote(' '.join(entry['options']))}")
               for path, entry in tree.items()]
    return f"""\
# bash completion for qzs {__version__}, generated by `qzs completion bash` from its parser.
# Load it with: eval "$(qzs completion bash)"
{_common_functions(tree)}{_lookups(commands, options)}_qzs() {{
    local cur="${{COMP_WORDS[COMP_CWORD]}}" prev="" command_path values
    [ "$COMP_CWORD" -gt 1 ] && prev="${{COMP_WORDS[COMP_CWORD-1]}}"
    command_path="$(_qzs_path "${{COMP_WORDS[@]:1:COMP_CWORD-1}}")"
    COMPREPLY=()
    if [ -n "$prev" ] && [[ "$prev" == -* ]] && _qzs_takes_value "$command_path" "$prev"; then
        values="$(_qzs_choices "$command_path" "$prev")"
        if [ -n "$values" ]; then
            COMPREPLY=($(compgen -W "$values" -- "$cur"))
        else
            compopt -o filenames 2>/dev/null
            COMPREPLY=($(compgen -f -- "$cur"))
        fi
    elif [[ "$cur" == -* ]]; then
        COMPREPLY=($(compgen -W "$(_qzs_options "$command_path")" -- "$cur"))
    elif [ -n "$(_qzs_commands "$command_path")" ]; then
        COMPREPLY=($(compgen -W "$(_qzs_commands "$command_path")" -- "$cur"))
    else
        compopt -o filenames 2>/dev/null
        COMPREPLY=($(compgen -W "$(_qzs_words "$command_path")" -- "$cur") $(compgen -f -- "$cur"))
    fi
}}
complete -F _qzs qzs
"""


def zsh_script(tree):
    """The zsh completion script of a command tree (:func:`command_tree`).

    Parameters
    ----------
    tree : dict
        What :func:`command_tree` returned.

    Returns
    -------
    str
        A script that defines ``_qzs`` (with each command's and option's help in the menu)
        and registers it with ``compdef``; saved as ``_qzs`` in ``$fpath`` it autoloads.
    """
    def described(items):
        return " ".join(_quote(f"{name.replace(':', chr(92) + ':')}:{text}")
                        for name, text in items.items())

    commands = [(path, f"described=({described(entry['commands'])})")
                for path, entry in tree.items() if entry["commands"]]
    options = [(path, f"described=({described(entry['options'])})")
               for path, entry in tree.items()]
    return f"""\
#compdef qzs
# zsh completion for qzs {__version__}, generated by `qzs completion zsh` from its parser.
# Load it with: eval "$(qzs completion zsh)" (after compinit), or save it as _qzs in $fpath.
{_common_functions(tree)}{_lookups(commands, options)}_qzs() {{
    local cur="${{words[CURRENT]}}" prev="${{words[CURRENT-1]}}" command_path values
    local -a described
    command_path="$(_qzs_path "${{(@)words[2,CURRENT-1]}}")"
    if (( CURRENT > 2 )) && [[ "$prev" == -* ]] && _qzs_takes_value "$command_path" "$prev"; then
        values="$(_qzs_choices "$command_path" "$prev")"
        if [[ -n "$values" ]]; then
            compadd -- ${{=values}}
        else
            _files
        fi
    elif [[ "$cur" == -* ]]; then
        _qzs_options "$command_path"
        _describe -t options 'option' described
    else
        _qzs_commands "$command_path"
        if (( ${{#described}} )); then
            _describe -t commands 'qzs command' described
        else
            values="$(_qzs_words "$command_path")"
            [[ -n "$values" ]] && compadd -- ${{=values}}
            _files
        fi
    fi
}}
if [[ "${{zsh_eval_context[-1]}}" == loadautofunc ]]; then
    _qzs "$@"
else
    compdef _qzs qzs
fi
"""


#: Shell -> the function that writes its script.
SHELLS = {"bash": bash_script, "zsh": zsh_script}
