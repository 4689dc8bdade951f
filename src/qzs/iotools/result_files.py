"""A result object's ``save(path)``: the format chosen by the file's extension (issue 42).

Every result class delegates its ``save`` here with what it has: a dataset (``.nc``,
``.csv``, ``.mat`` through :func:`qzs.iotools.writer.write_dataset`), a plain record
(``.json``) and, for a format of its own, a writer by extension. The extension is checked
before anything is computed or written (:func:`qzs.iotools.paths.check_output_path`: an
:class:`~qzs.errors.OutputPathError` naming ``path``, its extension and the accepted ones);
every file is written atomically (:func:`qzs.iotools.files.atomic_path`).
"""
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from qzs._format import json_text
from qzs.iotools.files import write_text
from qzs.iotools.paths import check_output_path

__all__ = ["DATASET_SUFFIXES", "RECORD_SUFFIXES", "save_by_extension", "save_doc",
           "suffixes_of", "write_json"]

#: The files a result with arrays writes (:func:`qzs.iotools.writer.write_dataset`).
DATASET_SUFFIXES = (".nc", ".csv", ".mat")
#: The file a result with a plain record writes (:func:`write_json`).
RECORD_SUFFIXES = (".json",)


def write_json(record: Mapping[str, Any], path: str | Path) -> Path:
    """Write ``record`` as strict JSON (NaN and inf as null), atomically.

    Parameters
    ----------
    record : mapping
        Plain data (:func:`qzs._format.json_text` converts arrays and numbers).
    path : str or Path
        The ``.json`` file; its folder is created if missing.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    WriteError
        Writing failed (disk full, permissions); nothing is left behind.
    """
    return write_text(path, json_text(record) + "\n")


def save_by_extension(path: str | Path, *, dataset: Callable[[], Any] | None = None,
                      record: Callable[[], Mapping[str, Any]] | None = None,
                      writers: Mapping[str, Callable[[Path], Path]] | None = None) -> Path:
    """Write a result to ``path`` in the format its extension names, atomically.

    Parameters
    ----------
    path : str or Path
        The file; its extension (case-insensitive) chooses the format.
    dataset : callable, optional
        Returns the result's ``xarray.Dataset`` (CF attributes, :func:`qzs.iotools.schema.
        to_dataset`); given, ``.nc``, ``.csv`` and ``.mat`` are accepted.
    record : callable, optional
        Returns the result as plain data; given, ``.json`` is accepted.
    writers : mapping of str to callable, optional
        Extension -> a writer of its own, called with the checked path (e.g. a spring
        fit's ``.toml``); it writes atomically and returns the path.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OutputPathError
        An extension the result cannot be written as (naming ``path``, the extension and
        the accepted ones), or a path that cannot be written; raised before any work.
    WriteError
        Writing failed; nothing is left behind.
    """
    writers = {suffix.lower(): write for suffix, write in (writers or {}).items()}
    accepted = [*(DATASET_SUFFIXES if dataset is not None else ()),
                *(RECORD_SUFFIXES if record is not None else ()), *writers]
    path = check_output_path(path, argument="path", suffixes=accepted)
    suffix = path.suffix.lower()
    if suffix in writers:
        return writers[suffix](path)
    if suffix in RECORD_SUFFIXES:
        return write_json(record(), path)  # type: ignore[misc]  # accepted only with it
    from qzs.iotools.writer import write_dataset

    return write_dataset(dataset(), path)  # type: ignore[misc]  # accepted only with it


def save_doc(formats: str) -> str:
    """The docstring every result's ``save`` shares, with what its extensions write.

    Parameters
    ----------
    formats : str
        What each extension writes (e.g. ".nc, .csv, .mat: the dataset"), wrapped into
        the docstring's first paragraph.

    Returns
    -------
    str
    """
    import textwrap

    head = textwrap.fill(f"Write the result atomically, the format chosen by the extension: "
                         f"{formats}.", width=88, subsequent_indent=" " * 8)
    return head + _SAVE_DOC


_SAVE_DOC = """

        Parameters
        ----------
        path : str or Path
            The file; its extension is one of ``save_suffixes``.

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        OutputPathError
            Another extension (naming ``path``, its extension and the accepted ones),
            raised before anything is computed or written.
        """


def suffixes_of(*, dataset: bool = False, record: bool = False,
                others: tuple[str, ...] = ()) -> tuple[str, ...]:
    """The extensions :func:`save_by_extension` accepts with these arguments.

    Parameters
    ----------
    dataset, record : bool
        Is a dataset, a record given?
    others : tuple of str
        The extensions of the ``writers`` given.

    Returns
    -------
    tuple of str
    """
    return (*(DATASET_SUFFIXES if dataset else ()), *(RECORD_SUFFIXES if record else ()),
            *others)


