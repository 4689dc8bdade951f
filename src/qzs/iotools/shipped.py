"""Files shipped with qzs (the paper's studies, example sweeps): list them, find one by name."""
from importlib import resources
from pathlib import Path

from qzs.errors import ParameterError

__all__ = ["shipped_files", "resolve_shipped"]


def shipped_files(folder):
    """Paths of the TOML files in a folder shipped inside the package, sorted by name.

    Parameters
    ----------
    folder : str
        Package-relative folder, e.g. ``"workflows/paper/study_files"``.
    """
    root = resources.files("qzs").joinpath(*folder.split("/"))
    return sorted(Path(str(p)) for p in root.iterdir() if p.name.endswith(".toml"))


def resolve_shipped(source, folder, what, plural):
    """``source`` as an existing path, or the shipped file of that name in ``folder``.

    A folder of a shipped file's name (the output folder a command names after it) does not
    hide the shipped file.

    A shipped file is named by its stem without a leading ``NN_`` order prefix
    (``stiction`` for ``02_stiction.toml``).

    Parameters
    ----------
    source : str or Path
        A path, or the name of a shipped file.
    folder : str
        Package-relative folder of the shipped files.
    what, plural : str
        What one file is and what several are, for the message (``study``, ``studies``).

    Raises
    ------
    ParameterError
        Neither a file nor a shipped name; the message lists the shipped names.
    """
    path = Path(source)
    names = {_name(p): p for p in shipped_files(folder)}
    if path.exists() and not (path.is_dir() and str(source) in names):
        return path  # a folder named as a shipped file (a command's output) is not the file
    if str(source) in names:
        return names[str(source)]
    raise ParameterError(f"{what} file not found: {str(source)!r}; shipped {plural} are "
                         f"{sorted(names)}.")


def _name(path):
    stem = path.stem
    prefix, _, rest = stem.partition("_")
    return rest if prefix.isdigit() and rest else stem
