"""Output paths checked before any long work starts: extension, folder, permissions, space.

:func:`check_output_path` answers in well under a second and writes nothing: a run that
would fail at its end (an unknown extension, a folder that cannot be made, a read-only
folder, a full disk) fails before it starts instead.

A missing parent folder is fine when it can be created (the atomic writer,
:func:`qzs.iotools.files.atomic_path`, creates it when it writes): its nearest existing
ancestor must be a writable directory. A file standing where a folder must go, or a
read-only folder, is an error.
"""
import contextlib
import os
import shutil
import tempfile
from pathlib import Path

from qzs._format import format_bytes
from qzs.errors import OutputPathError

__all__ = ["check_output_path", "free_name", "switch", "format_bytes", "removed_on_error"]


def check_output_path(path, *, argument, suffixes, estimated_bytes=None, directory=False,
                      overwrite=True):
    """Check that ``path`` can be written, before the work that produces it starts.

    Parameters
    ----------
    path : str or Path
        The file (or, with ``directory``, the folder) to be written.
    argument : str
        How the caller names it, for the message and the error's ``argument``
        (``"--out"`` on the command line, ``"out"`` in the API).
    suffixes : iterable of str or None
        Allowed extensions, with or without the leading dot, compared case-insensitively
        (``(".nc", ".csv")``); None accepts any name.
    estimated_bytes : int or float, optional
        Expected size of what will be written [bytes]; an error if the file system has
        less free space.
    directory : bool
        ``path`` is a folder to write files into (it may exist, as a directory).
    overwrite : bool
        May an existing output be replaced? If False, an existing file, or a folder holding
        anything, is an error naming the path and the flag (``--overwrite`` for an option,
        ``overwrite=True`` in the API): the command line's policy (``qzs docs
        command-line``); the API's writers replace, atomically.

    Returns
    -------
    Path
        ``path`` as a Path.

    Raises
    ------
    OutputPathError
        (a :class:`~qzs.errors.ParameterError`; attributes ``argument``, ``value`` and
        ``reason``) for an unknown extension, a directory where a file must go (or the
        reverse), a parent that is a file, a folder that is not writable, too little
        free space, (without ``overwrite``) an output that exists, or an empty name (``''``,
        which ``Path`` would read as the current folder).
    """
    if isinstance(path, str) and not path.strip():
        raise OutputPathError(argument, path, "is empty; give a file name" if not directory
                              else "is empty; give a folder name")
    path = Path(path)
    value = str(path)

    def fail(reason):
        raise OutputPathError(argument, value, reason)

    if suffixes is not None:
        allowed = tuple(dict.fromkeys("." + s.lower().lstrip(".") for s in suffixes))
        if path.suffix.lower() not in allowed:
            shown = " or ".join([", ".join(allowed[:-1]), allowed[-1]] if len(allowed) > 2
                                else allowed)
            got = f"extension {path.suffix!r}" if path.suffix else "no extension"
            fail(f"has {got}; it must end in {shown} (the format is chosen by the "
                 "extension)")
    if path.exists():
        if directory and not path.is_dir():
            fail("is a file, not a folder; choose a folder name")
        if not directory and path.is_dir():
            fail("is a folder; give a file name")
    existing = _nearest_existing(path if directory else path.parent)
    if not existing.is_dir():
        fail(f"cannot be created: {str(existing)!r} is a file, not a folder")
    target = path if directory and path.is_dir() else existing
    if not _writable(target):
        folder = Path(os.path.abspath(path if directory else path.parent))
        if target == folder:
            fail(f"cannot be written: the folder {str(target)!r} is read-only; choose a "
                 "writable folder")
        whose = "the" if directory else "its"
        fail(f"cannot be written: {whose} folder {str(folder)!r} does not exist and cannot be "
             f"created in the read-only folder {str(target)!r}; choose a writable folder")
    if estimated_bytes is not None:
        free = shutil.disk_usage(target).free
        if estimated_bytes > free:
            fail(f"needs about {format_bytes(estimated_bytes)} but only {format_bytes(free)} "
                 f"are free on the file system of {str(target)!r}; free some space or "
                 "choose another folder")
    if not overwrite and path.exists() and (not directory or any(path.iterdir())):
        flag = switch(argument, "overwrite")
        what, them = ("exists and holds files", "them") if directory else ("exists", "it")
        fail(f"{what}; pass {flag} to replace {them}, or choose another name")
    return path


class _Made:
    """What :func:`removed_on_error` yields: call :meth:`keep` once the output holds work
    worth keeping (then a later error leaves it for a resume)."""

    kept = False

    def keep(self):
        """Keep the output whatever happens next."""
        self.kept = True


@contextlib.contextmanager
def removed_on_error(path):
    """Remove the output a block makes at ``path`` if the block fails before keeping it.

    The store or folder of a long piece of work (a sweep, a design search) is made before
    its first result; an error after that (a refusal, a failed batch) would leave an empty
    one behind. Here ``path``, and the folders above it that did not exist either, are
    removed on an ``Exception`` unless the yielded object's ``keep()`` was called; an
    existing ``path`` is never removed (``overwrite`` replaced it on purpose), nor is
    anything on Ctrl-C or SIGTERM (what is stored stays for a resume).

    Parameters
    ----------
    path : str or Path
        The store, folder or file the block makes.

    Yields
    ------
    object
        With a ``keep()`` method.
    """
    path = Path(os.path.abspath(path))
    made = None  # the highest of path and its folders that the block will make
    probe = path
    while not probe.exists() and probe != probe.parent:
        made, probe = probe, probe.parent
    state = _Made()
    try:
        yield state
    except Exception:
        if made is not None and not state.kept:
            if made.is_dir():
                shutil.rmtree(made, ignore_errors=True)
            elif made.exists():
                made.unlink()
        raise


def switch(argument, name):
    """A yes/no option as the caller of ``argument`` spells it: ``--name`` on the command
    line (whose arguments are options, ``--out``), ``name=True`` in Python.

    Parameters
    ----------
    argument : str
        How the caller names the path a message is about (``"--out"``, ``"store"``).
    name : str
        The option's Python name (``"overwrite"``, ``"resume"``).

    Returns
    -------
    str
    """
    return f"--{name.replace('_', '-')}" if argument.startswith("--") else f"{name}=True"


def free_name(path, *, directory=False):
    """``path`` if nothing is in the way, else the first free ``STEM-2.SUFFIX``,
    ``STEM-3.SUFFIX``, ... beside it (``pi.zarr`` -> ``pi-2.zarr``, ``results`` ->
    ``results-2``).

    Parameters
    ----------
    path : str or Path
        The name a command would write to (its default).
    directory : bool
        ``path`` is a folder: an empty one is free (:func:`check_output_path` writes into it).

    Returns
    -------
    Path
    """
    path = Path(path)

    def free(candidate):
        return (not candidate.exists()
                or directory and candidate.is_dir() and not any(candidate.iterdir()))

    number = 1
    candidate = path
    while not free(candidate):
        number += 1
        candidate = path.with_name(f"{path.stem}-{number}{path.suffix}")
    return candidate


def _nearest_existing(folder):
    """``folder`` or its nearest ancestor that exists (the folder itself may be missing)."""
    folder = Path(os.path.abspath(folder))
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    return folder


def _writable(folder):
    """Can a file be created in ``folder``? Asked of the file system, leaving nothing.

    ``os.access`` answers from the permission bits, which root ignores; a probe file
    (an unnamed O_TMPFILE where the file system has it, else one removed at once)
    answers for read-only mounts and ACLs too.
    """
    if not os.access(folder, os.W_OK | os.X_OK):
        return False
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".qzs-probe-"):
            pass
    except OSError:
        return False
    return True
