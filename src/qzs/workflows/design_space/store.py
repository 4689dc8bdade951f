"""The optimiser's store: every evaluated design, generation by generation, in Zarr.

A Zarr (v3) group whose arrays grow along the evaluated designs:

- ``search_position`` (design, variable): where the optimiser asked (``log10`` for a
  log-scale variable), kept bit for bit so that a resumed run can check it is asked the
  same designs again;
- ``design_variables`` (design, variable) [their units]; ``generation`` (design);
- one array per metric column (design, sample) [the metric's unit], and ``status``
  (design, sample): 1 ok, 2 invalid parameters, 3 simulation failed, 4 analysis failed.

The group's attributes hold the problem's hash and document, the optimiser's seed and
population (a resume must ask for the same, :func:`check_same_search`), the integration step,
the designs and generations complete, and the failure messages. A generation is complete
once its rows are written and the attributes name it; rows beyond the count the
attributes give (an interrupted write) are cut off when the store is opened again, so an
interrupted run loses at most the generation being written.
"""
import json
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from qzs._version import __version__
from qzs.errors import OutputPathError, ResumeMismatchError
from qzs.iotools.paths import check_output_path

__all__ = ["DesignStore", "STORE_SUFFIX", "FORMAT", "SEARCH_SETTINGS", "check",
           "check_same_search", "stored_generations"]

STORE_SUFFIX = ".zarr"
FORMAT = "qzs-design-store-1"
#: The optimiser's settings a resumed search must share with its store: with another seed
#: or population NSGA-II asks for other designs than the stored ones.
SEARCH_SETTINGS = ("seed", "population")


class DesignStore:
    """A design store, created new or opened to resume.

    Parameters
    ----------
    path : str or Path
        The store (a folder named ``*.zarr``).
    problem : DesignProblem
        The problem; a resumed store must have been written for the same one.
    resume : bool
        Open an existing store and keep its generations.
    overwrite : bool
        Replace an existing store.
    argument : str
        How the caller names the path, for messages (``"--out"``, ``"store"``).

    Raises
    ------
    OutputPathError
        The name does not end in ``.zarr``, the folder cannot be written, the store exists
        without ``resume``/``overwrite``, ``resume`` names no store, or the store was
        written for another problem.
    ResumeMismatchError
        ``resume`` with another seed or population than the store was started with.
    ParameterError
        Both ``resume`` and ``overwrite``.
    """

    def __init__(self, path, problem, *, resume=False, overwrite=False, argument="store"):
        self.path, self.problem, self.argument = Path(path), problem, argument
        check(path, resume=resume, overwrite=overwrite, argument=argument)
        import zarr

        if resume:
            self.group = zarr.open_group(str(self.path), mode="r+")
            attrs = dict(self.group.attrs)
            if attrs.get("format") != FORMAT:
                raise OutputPathError(argument, path, "is not a design store written by "
                                      "`qzs optimize`; give its store, or start a new one")
            if attrs.get("problem_hash") != problem.hash:
                raise OutputPathError(argument, path, "was written for another problem file "
                                      f"({attrs.get('problem_name')!r}, a different hash); "
                                      "resume it with the file it was started with, or use "
                                      "--overwrite to start again")
            check_same_search(self.path, problem, attrs)
            self._trim()
        else:
            if overwrite and self.path.exists():
                import shutil

                shutil.rmtree(self.path)
            self.group = zarr.open_group(str(self.path), mode="w")
            self._create()

    # ------------------------------------------------------------ layout
    def _create(self):
        p = self.problem
        n_var, samples = len(p.variables), p.samples
        g = self.group
        g.create_array("search_position", shape=(0, n_var), chunks=(1024, n_var),
                       dtype="float64", fill_value=np.nan)
        g.create_array("design_variables", shape=(0, n_var), chunks=(1024, n_var),
                       dtype="float64", fill_value=np.nan)
        g.create_array("generation", shape=(0,), chunks=(4096,), dtype="int32", fill_value=-1)
        g.create_array("status", shape=(0, samples), chunks=(1024, samples), dtype="int8",
                       fill_value=0)
        for column in p.columns:
            g.create_array(f"metric_{column}", shape=(0, samples), chunks=(1024, samples),
                           dtype="float64", fill_value=np.nan)
        g.attrs.update({
            "format": FORMAT, "problem_name": p.name, "problem_title": p.title,
            "problem_hash": p.hash,
            "problem_document": json.dumps(p.document, sort_keys=True, default=str),
            "variables": [v.name for v in p.variables],
            "variable_units": [v.units for v in p.variables],
            "metric_columns": list(p.columns), "samples": samples,
            **{f"optimizer_{name}": p.optimizer[name] for name in SEARCH_SETTINGS},
            "designs_done": 0, "generations_done": 0, "messages": {},
            "qzs_version": __version__,
            "created": datetime.now(timezone.utc).isoformat(timespec="seconds")})

    def _arrays(self):
        names = ["search_position", "design_variables", "generation", "status"]
        return [self.group[n] for n in names] + [self.group[f"metric_{c}"]
                                                 for c in self.problem.columns]

    def _trim(self):
        """Cut rows an interrupted write left beyond the last complete generation."""
        done = self.designs
        for array in self._arrays():
            if array.shape[0] != done:
                array.resize((done, *array.shape[1:]))

    # ------------------------------------------------------------ reading
    @property
    def designs(self) -> int:
        """Designs stored in complete generations."""
        return int(self.group.attrs["designs_done"])

    @property
    def generations(self) -> int:
        """Complete generations."""
        return int(self.group.attrs["generations_done"])

    @property
    def step(self):
        """The integration step [s] and its note, once fixed (else None)."""
        attrs = self.group.attrs
        return (attrs["dt"], attrs.get("step_note", "")) if "dt" in attrs else None

    def set_step(self, dt, note):
        """Record the integration step every generation uses.

        Parameters
        ----------
        dt : float
            The step [s].
        note : str
            How it was chosen.
        """
        self.group.attrs.update({"dt": float(dt), "step_note": str(note)})

    def generation_rows(self, generation):
        """The stored rows of one complete generation.

        Parameters
        ----------
        generation : int
            The generation's number (0 first).

        Returns
        -------
        search_position : ndarray, shape (n, n_variables)
        values : dict of str to ndarray, shape (n, samples)
            Metric column -> values.
        status : ndarray of int8, shape (n, samples)
        """
        rows = np.flatnonzero(self.group["generation"][:] == generation)
        sl = slice(int(rows[0]), int(rows[-1]) + 1) if rows.size else slice(0, 0)
        values = {c: self.group[f"metric_{c}"][sl] for c in self.problem.columns}
        return self.group["search_position"][sl], values, self.group["status"][sl]

    def read(self):
        """Every stored design: a dict of arrays (see the module docstring)."""
        n = self.designs
        out = {"search_position": self.group["search_position"][:n],
               "design_variables": self.group["design_variables"][:n],
               "generation": self.group["generation"][:n], "status": self.group["status"][:n],
               "values": {c: self.group[f"metric_{c}"][:n] for c in self.problem.columns}}
        out["messages"] = {int(k): v for k, v in self.group.attrs.get("messages", {}).items()}
        return out

    # ------------------------------------------------------------ writing
    def append(self, generation, search_position, evaluation):
        """Store one generation's designs; it counts once every row is written.

        Parameters
        ----------
        generation : int
            The generation's number (0 first).
        search_position : ndarray, shape (n, n_variables)
            Where the optimiser asked.
        evaluation : Evaluation
            The designs' metrics (:func:`~qzs.workflows.design_space.evaluation.evaluate`).
        """
        start = self.designs
        n = len(search_position)
        stop = start + n
        rows = {"search_position": np.asarray(search_position, dtype=float),
                "design_variables": evaluation.designs,
                "generation": np.full(n, generation, dtype=np.int32),
                "status": evaluation.status}
        rows.update({f"metric_{c}": evaluation.values[c] for c in self.problem.columns})
        for name, values in rows.items():
            array = self.group[name]
            array.resize((stop, *array.shape[1:]))
            array[start:stop] = values
        messages = dict(self.group.attrs.get("messages", {}))
        for i, texts in enumerate(evaluation.messages):
            text = next((t for t in texts if t), "")
            if text:
                messages[str(start + i)] = text
        self.group.attrs.update({"designs_done": stop, "generations_done": generation + 1,
                                 "messages": messages})


def check(path: str | Path, *, resume: bool = False, overwrite: bool = False,
          argument: str = "store") -> None:
    """Check a store path before any work: name, folder, and resume/overwrite.

    Parameters
    ----------
    path : str or Path
        The store.
    resume, overwrite : bool
        As :class:`DesignStore` takes them.
    argument : str
        How the caller names the path.

    Raises
    ------
    OutputPathError, ParameterError
        As :class:`DesignStore`.
    """
    from qzs.workflows.sweeps.store import store_exists
    from qzs.workflows.sweeps.store_checks import check_resume

    check_resume(path, argument, resume, overwrite, work="the search")
    path = Path(path)
    check_output_path(path, argument=argument, suffixes=(STORE_SUFFIX,), directory=True)
    if path.exists() and not resume and not overwrite:
        raise OutputPathError(argument, path, store_exists(argument))


def check_same_search(path: str | Path, problem, attributes=None) -> None:
    """Refuse to resume a store with another seed or population than it was started with.

    Parameters
    ----------
    path : str or Path
        The store.
    problem : DesignProblem
        The problem as resumed, its ``optimizer`` settings with any override applied.
    attributes : mapping, optional
        The store's attributes, if already read.

    Raises
    ------
    ResumeMismatchError
        A setting of :data:`SEARCH_SETTINGS` differs from the stored one (a store written
        before they were recorded is checked by the replay alone).
    """
    if attributes is None:
        import zarr

        attributes = dict(zarr.open_group(str(path), mode="r").attrs)
    for name in SEARCH_SETTINGS:
        stored = attributes.get(f"optimizer_{name}")
        if stored is not None and stored != problem.optimizer[name]:
            raise ResumeMismatchError(name, stored, problem.optimizer[name], path)


def stored_generations(path: str | Path) -> int:
    """Complete generations in a design store (0 if there is none at ``path``).

    Parameters
    ----------
    path : str or Path
        The store.

    Returns
    -------
    int
    """
    import zarr

    try:
        done = zarr.open_group(str(path), mode="r").attrs.get("generations_done", 0)
        return done if isinstance(done, int) else 0
    except Exception:  # noqa: BLE001 - no store, or not a Zarr group: nothing kept
        return 0
