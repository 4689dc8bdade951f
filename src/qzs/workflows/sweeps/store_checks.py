"""A sweep's store checked before any case runs: its name, its folder, its room, resume.

:func:`check_store_path` (``qzs sweep`` calls it before it loads anything heavy) and
:func:`check_resume` (shared with the design space's store) refuse a store that would
fail later, each naming the argument, the value and the fix.
"""
from pathlib import Path

from qzs.engine.prepare import steps_per_sample
from qzs.errors import OutputPathError, ParameterError
from qzs.iotools.paths import check_output_path, switch
from qzs.workflows.sweeps.cases import batch_channels, case_duration, case_settings
from qzs.workflows.sweeps.definition import SweepDefinition, sample_cases
from qzs.workflows.sweeps.store import estimated_bytes, store_exists

__all__ = ["check_store_path", "check_resume", "check_store", "check_run_length",
           "time_samples", "STORE_SUFFIX", "BATCH_REMEDY"]

#: The extension of a sweep store: a Zarr folder, not a NetCDF file (``--out store.nc``
#: would make a folder named like a file of another format).
STORE_SUFFIX = ".zarr"



def time_samples(definition, settings):
    """Samples kept per time series (0 if none are kept).

    Before the step is chosen (``dt`` None), counted at the output period: the same
    count, give or take the last sample of a duration that is not a whole number of
    periods (enough for the size check made before any case runs).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : list of dict
        The varied parameters of each case (:func:`~qzs.workflows.sweeps.cases.case_settings`).

    Returns
    -------
    int
        Samples of the longest case's series at the output rate [samples].
    """
    if not definition.outputs["time_series"]:
        return 0
    longest = max(case_duration(definition, s) for s in settings)
    dt = definition.simulation["dt"] or 1.0 / definition.analysis["sample_rate"]
    decimation = steps_per_sample(definition.analysis["sample_rate"], dt)
    return int(round(longest / dt)) // decimation + 1



def check_store_path(definition: SweepDefinition, store: str | Path, *,
                     argument: str = "store", resume: bool = False,
                     overwrite: bool = False) -> None:
    """Check a sweep's store before any case runs: writable, room for it, not in the way.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    store : str or Path
        The Zarr store (a directory) to write.
    argument : str
        How the caller names the store, for the message (``"--out"``, ``"store"``).
    resume : bool
        The store will be continued: it may exist, and its size is not checked again.
    overwrite : bool
        The store will be replaced if it exists.

    Raises
    ------
    OutputPathError
        The store is not named ``*.zarr``, the folder cannot be written, the file system
        has less free space than the store's uncompressed size, the store exists without
        ``resume``/``overwrite``, or ``resume`` names no store.
    ParameterError
        Both ``resume`` and ``overwrite``.
    RunTooLongError, ResultTooLargeError
        A case that would take absurdly long, a batch that would not fit in memory
        (:func:`check_run_length`).
    """
    check_resume(store, argument, resume, overwrite)
    settings = case_settings(definition, sample_cases(definition))
    check_run_length(definition, settings, cases=min(definition.batch_size, len(settings)))
    check_store(definition, store, time_samples(definition, settings), argument=argument,
                 resume=resume, overwrite=overwrite)



#: What to do about a batch whose samples would not fit in memory, in a sweep file's words.
BATCH_REMEDY = ("shorten the cases ([excitation] duration, [analysis] duration or n_averages), "
                "lower [analysis] sample_rate, or run fewer cases at once ([sweep] batch_size)")


def check_run_length(definition, settings, *, cases=1, threads=None, remedy=BATCH_REMEDY):
    """Refuse, before any probe or store, a sweep whose longest case alone would take
    absurdly long (:func:`qzs.engine.driver.plan_run`'s limit), or whose batch of ``cases``
    such cases would keep more samples than the memory holds (what
    :func:`qzs.engine.batch.simulate_batch` refuses when it runs, and ``qzs simulate``
    before its run: :func:`qzs.engine.driver.check_memory`).

    Before the step is chosen (``dt`` None) the output period stands for it: the step is
    never longer, so the count of steps is a lower bound and a refusal is certain. The
    samples are counted at the output rate, whatever the step.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : list of dict
        Its cases' varied parameters (:func:`qzs.workflows.sweeps.cases.case_settings`).
    cases : int
        Cases stepped together (a batch's) [-].
    threads : int, optional
        Threads they are shared over [-]; default the machine's cores.
    remedy : str
        The memory message's advice (default in the words of a sweep file).

    Raises
    ------
    RunTooLongError
        Even one case would take more than a day at the kernel's best speed.
    ResultTooLargeError
        The batch's samples (:func:`qzs.workflows.sweeps.cases.batch_channels`) would take
        more than half the memory available.
    """
    from qzs._validation import worker_count
    from qzs.engine.channels import sample_bytes
    from qzs.engine.driver import check_memory, plan_run

    dt = definition.simulation["dt"]
    if dt is None:
        dt = 1.0 / definition.analysis["sample_rate"]
    duration = max((case_duration(definition, s) for s in settings),
                   default=definition.analysis["duration"])
    plan_run(duration, dt, 1, kernel="lanes", cases=cases,
             workers=worker_count(threads, cases))
    rate = definition.analysis["sample_rate"]
    samples = int(round(duration * rate)) + 1
    check_memory(cases * samples * sample_bytes(batch_channels(definition)), duration, rate,
                 remedy)


def check_resume(store, argument, resume, overwrite, work="the sweep"):
    """``resume`` and ``overwrite`` together, or ``resume`` of no store, are errors.

    Parameters
    ----------
    store : str or Path
        The store (a sweep's or a design search's).
    argument : str
        How the caller names it (``"--out"``, ``"store"``).
    resume, overwrite : bool
        What was asked for.
    work : str
        What leaving out ``resume`` starts, for the message.

    Raises
    ------
    ParameterError
        Both ``resume`` and ``overwrite``.
    OutputPathError
        ``resume`` of a store that does not exist.
    """
    resume_switch, overwrite_switch = switch(argument, "resume"), switch(argument, "overwrite")
    if resume and overwrite:
        raise ParameterError(f"{resume_switch} continues the store and {overwrite_switch} "
                             "replaces it: give one of them, not both.")
    if resume and not Path(store).exists():
        raise OutputPathError(argument, store, "does not exist, so there is nothing to resume; "
                              f"check the name, or leave out {resume_switch} to start {work}")



def check_store(definition, store, n_time, *, argument, resume, overwrite):
    """Check a sweep's store of ``n_time`` samples per series: writable, room, not in the way.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    store : str or Path
        The Zarr store (a directory) to write.
    n_time : int
        Samples kept per time series (:func:`time_samples`) [samples].
    argument : str
        How the caller names the store, for the message (``"--out"``, ``"store"``).
    resume : bool
        The store will be continued: its size is not checked again.
    overwrite : bool
        The store will be replaced if it exists.

    Raises
    ------
    OutputPathError
        The store is not named ``*.zarr``, the folder cannot be written, the file system
        has less free space than the store's uncompressed size, or the store exists
        without ``resume``/``overwrite``.
    """
    size = None if resume else estimated_bytes(definition, n_time)
    check_output_path(store, argument=argument, suffixes=(STORE_SUFFIX,), directory=True,
                      estimated_bytes=size)
    if Path(store).exists() and not resume and not overwrite:
        raise OutputPathError(argument, store, store_exists(argument))


