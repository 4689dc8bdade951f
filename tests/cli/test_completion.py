"""``qzs completion bash|zsh`` (qzs.cli.completion): scripts generated from the parser that
the shells load and that complete subcommands, options, choices and topics."""
import shutil
import subprocess

import pytest

from qzs.cli import build_parser, main
from qzs.cli.completion import bash_script, command_tree, zsh_script


@pytest.fixture(scope="module")
def tree():
    return command_tree(build_parser())


@pytest.fixture(scope="module")
def bash_file(tmp_path_factory, tree):
    path = tmp_path_factory.mktemp("completion") / "qzs.bash"
    path.write_text(bash_script(tree))
    return path


def test_the_tree_is_the_parsers(tree):
    parser = build_parser()
    top = next(a for a in parser._actions if a.dest == "command")
    assert list(tree[""]["commands"]) == list(top.choices)
    assert {"hexapod simulate", "hexapod study", "docs", "completion"} <= set(tree)
    assert tree["simulate"]["values"]["--solver"] == ["ode3", "rk4", "euler"]
    assert tree["simulate"]["values"]["--config"] == []        # a value, any name: files
    assert "--json" not in tree["simulate"]["values"]            # a flag takes no value
    assert "model" in tree["docs"]["words"] and "simulate" in tree["docs"]["words"]
    assert tree["completion"]["words"] == ["bash", "zsh"]
    for path, entry in tree.items():
        assert "--help" in entry["options"], path


def complete(script, words, cwd):
    """What bash completes for ``words`` (the last one is being typed), as a list."""
    program = (f'source {script}\nCOMP_WORDS=({" ".join(repr(w) for w in words)})\n'
               "COMP_CWORD=$((${#COMP_WORDS[@]} - 1))\n_qzs\n"
               'printf "%s\\n" "${COMPREPLY[@]}"\n')
    done = subprocess.run(["bash", "--norc", "-c", program], capture_output=True, text=True,
                          cwd=cwd, check=True)
    assert done.stderr == ""
    return done.stdout.split()


@pytest.mark.skipif(shutil.which("bash") is None, reason="no bash")
@pytest.mark.parametrize("words, expected", [
    (["qzs", "simu"], ["simulate"]),
    (["qzs", "simulate", "--to"], ["--tolerance", "--tolerance-state"]),
    (["qzs", "simulate", "--solver", ""], ["ode3", "rk4", "euler"]),
    (["qzs", "simulate", "--solver", "rk4", "--dur"], ["--duration"]),
    (["qzs", "s"], ["simulate", "study", "sweep", "sweep-plot", "sweep-export",
                    "sensitivity"]),
    (["qzs", "hexapod", ""], ["linear", "simulate", "transmissibility", "study"]),
    (["qzs", "hexapod", "simulate", "--axis", "r"], ["rx", "ry", "rz"]),
    (["qzs", "hexapod", "--config", "x.toml", "st"], ["study"]),   # skips an option's value
    (["qzs", "docs", "mo"], ["model"]),
    (["qzs", "completion", ""], ["bash", "zsh"]),
    (["qzs", "experiment", "--wr"], ["--write-map"]),
    (["qzs", "--v"], ["--version"]),
])
def test_bash_completes_from_the_parser(bash_file, tmp_path, words, expected):
    assert complete(bash_file, words, tmp_path) == expected


@pytest.mark.skipif(shutil.which("bash") is None, reason="no bash")
def test_bash_completes_file_names_for_file_options(bash_file, tmp_path):
    (tmp_path / "run.toml").write_text("")
    assert complete(bash_file, ["qzs", "simulate", "--config", "ru"], tmp_path) == ["run.toml"]
    assert complete(bash_file, ["qzs", "study", "ru"], tmp_path) == ["run.toml"]


def test_the_command_prints_the_script(capsys, tree):
    assert main(["completion", "bash"]) == 0
    assert capsys.readouterr().out == bash_script(tree)
    assert main(["completion", "zsh"]) == 0
    assert capsys.readouterr().out == zsh_script(tree)
    assert main(["completion", "fish"]) == 2
    assert "invalid choice: 'fish'" in capsys.readouterr().err


ZSH_STUBS = """
autoload -U compinit && compinit -u
source {script}
compadd() {{ while [[ "$1" == -* && "$1" != "--" ]]; do shift; done; [[ "$1" == "--" ]] && shift;
            print -r -- "$@"; }}
_describe() {{ local name; for name in "${{(@P)4}}"; do print -r -- "${{name%%:*}}"; done; }}
_files() {{ print -r -- FILES; }}
words=({words}); CURRENT=${{#words}}
_qzs
"""


@pytest.mark.skipif(shutil.which("zsh") is None, reason="no zsh (apt-get install zsh)")
@pytest.mark.parametrize("words, offered", [
    (["qzs", ""], {"simulate", "docs", "completion", "hexapod"}),
    (["qzs", "simulate", "--"], {"--tolerance", "--solver", "--help"}),
    (["qzs", "simulate", "--solver", ""], {"ode3", "rk4", "euler"}),
    (["qzs", "hexapod", "simulate", "--axis", ""], {"x", "rz"}),
    (["qzs", "docs", ""], {"model", "simulate", "FILES"}),
    (["qzs", "simulate", "--config", ""], {"FILES"}),
])
def test_zsh_loads_the_script_and_offers_the_parsers_words(tmp_path, tree, words, offered):
    """``zsh -n`` accepts the script; with zsh's menu functions stubbed, ``_qzs`` offers the
    words the parser has (zsh filters them by the typed prefix itself)."""
    script = tmp_path / "_qzs"
    script.write_text(zsh_script(tree))
    subprocess.run(["zsh", "-n", str(script)], check=True)
    program = ZSH_STUBS.format(script=script, words=" ".join(repr(w) for w in words))
    done = subprocess.run(["zsh", "-f", "-c", program], capture_output=True, text=True,
                          cwd=tmp_path, check=True)
    assert offered <= set(done.stdout.split()), done.stdout + done.stderr
