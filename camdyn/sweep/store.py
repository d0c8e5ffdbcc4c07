"""Where a sweep's finished points go, and the labelled Dataset they are assembled into.

A sweep with ``out="map.nc"`` streams into the folder ``map.nc.parts/`` as chunks finish:

``lock``
    held by the process that writes the folder (see :class:`FolderLock`): a second process
    that would start or resume the same sweep is refused while the first runs;
``sweep.pickle``
    the :class:`~camdyn.sweep.spec.SweepSpec` (rig, scene, grid, measure, settings), for resume;
``manifest.json``
    the same for people: the grid, the attributes of the final file, the number of points;
``chunks/points-<first>-<last>.nc``
    one small netCDF3 file per finished chunk: each point's flat index, outcome, message and
    measured values.

Every file is written under a temporary name and renamed into place (atomic on POSIX), so a
sweep killed at any moment leaves only whole files; a chunk file that cannot be read is
deleted and its points run again.  :func:`assemble` builds the Dataset from the chunks alone,
so a sweep resumed from its folder equals one that was never interrupted, value for value.
When every point has run, the Dataset is written to ``map.nc`` (again by rename) and the
folder removed; points that could not run keep the folder, so that ``resume`` can run them.
Where ``map.nc`` goes is checked before any point runs (:func:`check_out`): a folder, a missing
or read-only parent folder is refused, and so is a finished ``map.nc`` unless ``overwrite``.

Why a folder of netCDF3 files rather than one growing file: the netCDF3 writer (SciPy's, the
one camdyn already depends on) cannot append in place without rewriting the file, and one file
per chunk makes every write small, atomic and independent of the others (a crash can never
damage a finished point).  zarr would do the same but is not a dependency.
"""
from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import pickle
import shutil
import threading
from pathlib import Path
from typing import Callable, Iterable

try:
    import fcntl
except ImportError:  # not POSIX (Windows): sweep folders are not locked (FolderLock says so)
    fcntl = None

import numpy as np

from .._version import __version__
from ..errors import CamdynError
from ..model.rig import PARAMETERS
from .spec import ALL_CODES, NOT_RUN, OWN, ChunkResult, SweepSpec

FORMAT = "camdyn sweep folder 1"
TITLE = "camdyn parameter sweep"
PENDING = "not run yet: resume the sweep to run it"
log = logging.getLogger("camdyn.sweep.api")


class StoreError(CamdynError, ValueError):
    """A sweep's output or folder cannot be created, found, read or used now (another process
    holds it); the message names the file and what to do."""


class NotASweepError(StoreError):
    """A file given to resume or read as a sweep is not a camdyn sweep file (or is damaged)."""


def parts_folder(out) -> Path:
    """The folder a sweep writing ``out`` streams into: ``<out>.parts``."""
    return Path(os.fspath(out) + ".parts")


class MemoryStore:
    """Finished chunks kept in memory (a sweep without ``out``)."""

    def __init__(self):
        self._chunks: list[ChunkResult] = []

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        pass

    def put(self, chunk: ChunkResult) -> None:
        self._chunks.append(chunk)

    def chunks(self) -> list[ChunkResult]:
        return list(self._chunks)


def check_out(out, overwrite: bool = False) -> None:
    """Refuse, before any work, an ``out`` the sweep could not write or must not replace."""
    path, folder = Path(out), parts_folder(out)
    if folder.exists():
        refuse_if_in_use(out)
        raise StoreError(f"{folder} holds an unfinished sweep: resume it (camdyn.sweep.api.resume({str(out)!r}) or "
                         f"'camdyn sweep --resume {out}'), or delete that folder to start again")
    if path.is_dir():
        raise StoreError(f"{path} is a folder: give the sweep a file name to write (e.g. {path / 'sweep.nc'})")
    parent = path.absolute().parent
    if not parent.is_dir():
        raise StoreError(f"{path}: the folder {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise StoreError(f"{path}: the folder {parent} is not writable")
    if path.exists() and not overwrite:
        raise StoreError(f"{path} exists: choose another file, or replace it with overwrite=True "
                         "('camdyn sweep --overwrite')")


def refuse_if_in_use(out) -> None:
    """StoreError, naming the process, if a process writes the folder of the sweep ``out``."""
    FolderLock(parts_folder(out)).refuse_if_held()


class FolderLock:
    """The lock of a sweep folder, held while a process writes it, so that a second process
    that would resume (or start) the same sweep is refused rather than run the same points and
    race the first to assemble and remove the folder.

    It is a POSIX record lock (``fcntl.lockf``) on the file ``lock`` in the folder, which also
    holds the owner's process id for the message.  The operating system releases it when the
    process ends, however it ends (SIGKILL included), so a killed sweep never leaves a stale
    lock.  A record lock belongs to the process, not to an open file: process-pool workers
    forked from the owner do not hold it (an ``flock`` would be inherited, and kept by workers
    that outlive a killed parent); within one process a set of held folders does the refusing.
    Where there is no ``fcntl`` (Windows) or the file system refuses locks (some network file
    systems) the folder is not locked: a warning says so.
    """

    _held: set[str] = set()
    _guard = threading.Lock()

    def __init__(self, folder: Path):
        self.folder = Path(folder)
        self.path = self.folder / "lock"
        self.key = str(self.folder.resolve())
        self.file = None

    def acquire(self) -> None:
        with self._guard:
            self._refuse_if_held_here()
            if fcntl is None:
                log.warning("%s: this platform has no fcntl, so the folder is not locked: do not resume it in "
                            "two processes at once", self.folder)
            else:
                self._lock()
            self._held.add(self.key)

    def _lock(self) -> None:
        """Take the OS lock (where the file system cannot lock: a warning)."""
        file = open(self.path, "a+")
        try:
            fcntl.lockf(file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except (BlockingIOError, PermissionError):
            file.close()
            self.refuse_if_held()
            raise StoreError(f"{self.folder} is in use by another camdyn sweep: wait for it to finish") from None
        except OSError as exc:
            file.close()
            log.warning("%s cannot be locked (%s): do not resume it in two processes at once", self.path, exc)
            return
        if not _same_file(file, self.path):  # the owner finished and removed the folder while this waited
            file.close()
            raise StoreError(f"{self.folder} was finished and removed by another process just now: its file "
                             f"{str(self.folder)[:-len('.parts')]} has the result")
        file.seek(0)
        file.truncate()
        file.write(f"{os.getpid()}\n")
        file.flush()
        self.file = file

    def _refuse_if_held_here(self) -> None:
        if self.key in self._held:
            raise StoreError(f"{self.folder} is in use by this process (another sweep or resume still runs on "
                             "it): wait for that one to finish")

    def refuse_if_held(self) -> None:
        """Raise StoreError, naming the process, if a process (this one or another) holds the lock."""
        self._refuse_if_held_here()
        if fcntl is None or not self.path.exists():
            return
        with open(self.path, "r+") as file:   # opened here: this process holds no lock on it
            try:
                fcntl.lockf(file, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except (BlockingIOError, PermissionError):
                owner = file.read().strip() or "unknown"
                raise StoreError(f"{self.folder} is in use by another camdyn sweep (process {owner}): wait for it "
                                 "to finish, or stop that process") from None
            except OSError:
                return
            fcntl.lockf(file, fcntl.LOCK_UN)

    def release(self) -> None:
        with self._guard:
            self._held.discard(self.key)
            if self.file is not None:
                self.file.close()   # releases the record lock
                self.file = None


def _same_file(file, path: Path) -> bool:
    try:
        return os.path.samestat(os.fstat(file.fileno()), os.stat(path))
    except FileNotFoundError:
        return False


class FolderStore:
    """Finished chunks as files in ``<out>.parts/`` (see the module doc), written by the process
    holding its lock: ``create`` and ``open`` take it, leaving the ``with`` block releases it."""

    def __init__(self, out):
        self.out = Path(out)
        self.folder = parts_folder(out)
        self.lock = FolderLock(self.folder)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.lock.release()

    @classmethod
    def create(cls, out, spec: SweepSpec, overwrite: bool = False) -> "FolderStore":
        check_out(out, overwrite)
        store = cls(out)
        try:
            store.folder.mkdir()
        except FileExistsError:  # another process started the same sweep since check_out
            check_out(out, overwrite)
            raise
        try:
            store.lock.acquire()
            store._describe(spec)
        except BaseException:  # nothing half made is left behind
            store.lock.release()
            shutil.rmtree(store.folder, ignore_errors=True)
            raise
        return store

    def _describe(self, spec: SweepSpec) -> None:
        _atomic(self.folder / "sweep.pickle", lambda p: p.write_bytes(pickle.dumps(spec)))
        manifest = {"format": FORMAT, "out": str(self.out), "points": spec.size,
                    "grid": {k: v.tolist() for k, v in spec.axes.items()}, "attributes": attributes(spec)}
        _atomic(self.folder / "manifest.json", lambda p: p.write_text(json.dumps(manifest, indent=1) + "\n"))
        (self.folder / "chunks").mkdir()

    @classmethod
    def open(cls, out, lock: bool = True) -> "FolderStore":
        """The folder of the unfinished sweep writing ``out``; locked unless ``lock`` is False
        (to read it only)."""
        store = cls(out)
        if not (store.folder / "sweep.pickle").is_file():
            raise StoreError(f"{out}: no sweep to resume ({store.folder} does not hold one)")
        if lock:
            store.lock.acquire()
        return store

    def manifest(self) -> dict:
        """The folder's manifest.json, checked (StoreError naming it if missing or damaged)."""
        path = self.folder / "manifest.json"
        try:
            manifest = json.loads(path.read_text())
        except FileNotFoundError:
            raise StoreError(f"{path} is missing: the folder is damaged; delete {self.folder} to start the sweep "
                             "again") from None
        except (OSError, ValueError) as exc:
            raise StoreError(f"{path} cannot be read ({_first_line(exc)}): the folder is damaged; delete "
                             f"{self.folder} to start the sweep again") from None
        if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
            found = manifest.get("format") if isinstance(manifest, dict) else None
            raise StoreError(f"{path}: format {found!r}, this camdyn reads {FORMAT!r}")
        if not isinstance(manifest.get("attributes"), dict) or not isinstance(manifest.get("grid"), dict):
            raise StoreError(f"{path} has no 'attributes' or 'grid': the folder is damaged; delete {self.folder} "
                             "to start the sweep again")
        return manifest

    def spec(self) -> SweepSpec:
        written = self.manifest()["attributes"].get("camdyn_version")
        if written != __version__:
            log.warning("%s was started by camdyn %s; this is camdyn %s", self.folder, written, __version__)
        path = self.folder / "sweep.pickle"
        try:
            spec = pickle.loads(path.read_bytes())
        except (ImportError, AttributeError) as exc:   # a class the pickle names is not found here
            raise StoreError(f"{path} cannot be read ({_first_line(exc)}): the measure must be importable where "
                             "the sweep is resumed (not defined in __main__)") from exc
        except Exception as exc:
            raise StoreError(f"{path} is damaged ({_first_line(exc)}): delete {self.folder} to start the sweep "
                             "again") from None
        if not isinstance(spec, SweepSpec):
            raise StoreError(f"{path} holds a {type(spec).__name__}, not a sweep: delete {self.folder} to start "
                             "the sweep again")
        return spec

    def put(self, chunk: ChunkResult) -> None:
        name = f"points-{int(chunk.index[0]):09d}-{int(chunk.index[-1]):09d}.nc"
        _atomic(self.folder / "chunks" / name, lambda p: chunk_dataset(chunk).to_netcdf(p, engine="scipy"))

    def chunks(self) -> list[ChunkResult]:
        out = []
        for path in sorted((self.folder / "chunks").glob("points-*.nc")):
            try:
                out.append(_read_chunk(path))
            except Exception as exc:  # a damaged file: its points run again
                log.warning("%s cannot be read (%s); its points will run again", path, _netcdf3_problem(path, exc))
                path.unlink(missing_ok=True)
        return out

    def finish(self, ds, complete: bool) -> None:
        """Write the Dataset to ``out``; remove the folder once every point has run."""
        _atomic(self.out, lambda p: ds.to_netcdf(p, engine="scipy"))
        if complete:
            shutil.rmtree(self.folder)


def _read_chunk(path: Path) -> ChunkResult:
    import xarray as xr

    ds = xr.load_dataset(path, engine="scipy")
    return ChunkResult(ds["point_index"].values.astype(np.int64), ds["outcome"].values.astype(np.int32),
                       [str(m) for m in ds["message"].values],
                       {name: (v.dims[1:], v.values.astype(float)) for name, v in ds.data_vars.items()
                        if name not in OWN})


def load_sweep(out):
    """The Dataset of a finished sweep file; :class:`NotASweepError` (one line: the file and what
    it lacks) for a file that is not one."""
    import xarray as xr

    path = Path(out)
    try:
        ds = xr.load_dataset(path, engine="scipy")
    except OSError as exc:
        raise StoreError(f"{path} cannot be read ({exc.strerror or exc})") from None
    except Exception as exc:
        raise NotASweepError(f"{path} is not a camdyn sweep: {_netcdf3_problem(path, exc)}") from None
    title = ds.attrs.get("title")
    if title != TITLE:
        run = " (a saved run, as 'camdyn simulate --netcdf' writes)" if str(title).startswith("camdyn run") else ""
        raise NotASweepError(f"{path} is not a camdyn sweep: its title is {title!r}, not {TITLE!r}{run}")
    names = ["outcome", "message"] + str(ds.attrs.get("grid", "")).split()
    missing = [name for name in names if name not in ds.variables] + ([] if "grid" in ds.attrs else ["grid attribute"])
    if missing:
        raise NotASweepError(f"{path} is not a whole camdyn sweep: it has no {missing[0]!r}")
    return ds


def _netcdf3_problem(path: Path, exc: Exception) -> str:
    """What is wrong with a file the netCDF3 reader refused, in a few words."""
    try:
        with open(path, "rb") as file:
            head = file.read(4)
    except OSError:
        head = b"CDF"
    if not head:
        return "the file is empty"
    if head == b"\x89HDF":
        return "it is a netCDF4/HDF5 file (camdyn writes netCDF3)"
    if not head.startswith(b"CDF"):
        return "it is not a netCDF3 file"
    return _first_line(exc)


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {lines[0]}" if lines else type(exc).__name__


def _atomic(path: Path, write: Callable[[Path], object]) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def chunk_dataset(chunk: ChunkResult):
    """A chunk as a small Dataset along ``point`` (its file's content)."""
    import xarray as xr

    data = {"point_index": ("point", chunk.index.astype(np.int32)), "outcome": ("point", chunk.outcome),
            "message": ("point", np.array(chunk.message, dtype=object))}
    data.update({name: (("point",) + tuple(dims), block) for name, (dims, block) in chunk.values.items()})
    return xr.Dataset(data, attrs={"title": "camdyn sweep chunk", "camdyn_version": __version__})


def done_mask(spec: SweepSpec, chunks: Iterable[ChunkResult]) -> np.ndarray:
    done = np.zeros(spec.size, dtype=bool)
    for chunk in chunks:
        done[chunk.index] = True
    return done


def assemble(spec: SweepSpec, chunks: Iterable[ChunkResult], not_run: dict[int, str] | None = None):
    """The labelled Dataset: one dim per grid name (in the grid's order), the measured variables
    (float, NaN where a point has none), ``outcome`` and ``message``; a point in no chunk is
    NOT_RUN, with its message from ``not_run`` or "not run yet"."""
    import xarray as xr

    chunks = sorted(chunks, key=lambda c: int(c.index[0]))
    n = spec.size
    outcome = np.full(n, NOT_RUN, dtype=np.int32)
    message = np.full(n, PENDING, dtype=object)
    dims_of, width = {}, {}
    for c in chunks:
        for name, (dims, block) in c.values.items():
            dims_of.setdefault(name, tuple(dims))
            for d, w in zip(dims, block.shape[1:]):
                width[d] = max(width.get(d, 1), w)
    columns = {name: np.full((n,) + tuple(width[d] for d in dims), np.nan) for name, dims in dims_of.items()}
    for c in chunks:
        outcome[c.index] = c.outcome
        message[c.index] = np.array(c.message, dtype=object)
        for name, (_, block) in c.values.items():
            columns[name][(c.index,) + tuple(slice(0, w) for w in block.shape[1:])] = block
    for index, text in (not_run or {}).items():
        message[index] = text
    grid, shape = spec.names, spec.shape
    described = variable_attributes(spec)
    data = {name: (grid + dims_of[name], col.reshape(shape + col.shape[1:]), described.get(name, {}))
            for name, col in columns.items()}
    data["outcome"] = (grid, outcome.reshape(shape), described["outcome"])
    data["message"] = (grid, message.reshape(shape), described["message"])
    coords = {name: (name, a, described[name]) for name, a in spec.axes.items()}
    ds = xr.Dataset(data, coords=coords, attrs=attributes(spec))
    if "revolutions_run" in ds:
        ds.attrs.update(stop_saving(ds, spec))
    return spec.finish(ds, spec) if spec.finish is not None else ds


# --- self-describing attributes: one place, so that they can share code with the run writer ---
def attributes(spec: SweepSpec) -> dict:
    """The global attributes of a sweep file: what was swept, on what, how (no timestamps:
    the same sweep gives the same file)."""
    rig, scene = spec.rig, spec.scene
    attrs = {"title": TITLE, "source": f"camdyn {__version__}", "camdyn_version": __version__,
             "grid": " ".join(spec.names), "points": spec.size, "scene": scene.slug}
    attrs.update({f"scene_{k}": v for k, v in dataclasses.asdict(scene).items()})
    attrs.update({"rig": rig.name, "rig_description": rig.description, "rig_follower": rig.follower,
                  "rig_source": rig.origin or "not recorded (a Rig built in code)"})
    attrs.update({f"rig_{p.name}": getattr(rig, p.name) for p in PARAMETERS if getattr(rig, p.name) is not None})
    attrs["rig_units"] = ", ".join(f"{p.name} {_unit(p.unit)}" for p in PARAMETERS)
    attrs["measure"] = repr(spec.measure)
    if dataclasses.is_dataclass(spec.measure):
        attrs.update({f"measure_{f.name}": _attr(getattr(spec.measure, f.name))
                      for f in dataclasses.fields(spec.measure)})
    attrs.update({f"simulate_{k}": _attr(v) for k, v in sorted(spec.record().items())})
    if spec.samples_per_revolution is not None:
        attrs["samples_per_revolution"] = spec.samples_per_revolution
    attrs["outcome_codes"] = ", ".join(f"{code}={name}" for name, code in ALL_CODES.items())
    return attrs


def variable_attributes(spec: SweepSpec) -> dict[str, dict]:
    """units and long_name of the grid coordinates, the sweep's variables and, where the
    measure says (its ``variables``: name -> (long_name, units)), the measured ones."""
    out = {"speed_rpm": {"units": "rev/min", "long_name": "cam speed (> 0 counter-clockwise)"},
           "outcome": {"long_name": "how the point's run ended (see flag_meanings)",
                       "flag_values": np.array(list(ALL_CODES.values()), dtype=np.int32),
                       "flag_meanings": " ".join(ALL_CODES)},
           "message": {"long_name": "why the point's run did not succeed (empty on success)"}}
    out.update({p.name: {"units": _unit(p.unit), "long_name": p.description} for p in PARAMETERS})
    out["alpha_start"] = {"units": "rad", "long_name": "follower angle alpha at the run's start (its y0)"}
    out["alpha_dot_start"] = {"units": "rad/s", "long_name": "follower rate alpha_dot at the run's start (its y0)"}
    out["revolutions_run"] = {"units": "1", "long_name": "cam revolutions integrated (fewer than requested where "
                                                         "the run stopped once periodic: see stop_period)"}
    out["stop_period"] = {"units": "1", "long_name": "minimal period (revolutions) of the cycle the run converged to "
                                                     "within the stop threshold, with no shorter cycle still settling "
                                                     "(camdyn.StopWhenPeriodic.period_of), repeated to the requested "
                                                     "length; 0: not converged, run to its end"}
    for name, (long_name, units) in getattr(spec.measure, "variables", {}).items():
        out[name] = {"units": units, "long_name": long_name}
    return out


def stop_saving(ds, spec: SweepSpec) -> dict:
    """The attributes that say what stopping converged runs saved: revolutions requested and run
    (summed over the points that ran) and the points that stopped."""
    ran = np.isfinite(ds["revolutions_run"].values)
    requested = spec.request.span.revolutions
    total = float(requested) * int(np.sum(ran)) if requested is not None else math.nan
    return {"revolutions_requested_total": total,
            "revolutions_run_total": float(np.nansum(ds["revolutions_run"].values)),
            "points_stopped_converged": int(np.sum(ds["stop_period"].values > 0))}


def stop_summary(ds) -> str:
    """One line: how many of the points that ran stopped once periodic, and the revolutions saved."""
    a = ds.attrs
    ran = int(np.sum(np.isfinite(ds["revolutions_run"].values)))
    requested, run = a["revolutions_requested_total"], a["revolutions_run_total"]
    text = f"stopped once periodic: {a['points_stopped_converged']} of the {ran} points that ran"
    if not math.isfinite(requested) or requested <= 0:
        return f"{text}; {run:.6g} revolutions run"
    saved = requested - run
    return f"{text}; {run:.6g} of {requested:.6g} revolutions run, {saved:.6g} ({100 * saved / requested:.0f} %) saved"


def rig_of(attrs: dict):
    """The base rig of a sweep file, read back from its attributes."""
    from ..model.rig import Rig

    values = {p.name: attrs[f"rig_{p.name}"] for p in PARAMETERS if f"rig_{p.name}" in attrs}
    return Rig(**values, name=attrs.get("rig", "unnamed"), description=attrs.get("rig_description", ""),
               follower=attrs.get("rig_follower", "oscillating"))  # a file from before the follower types


def scene_of(attrs: dict):
    """The scene of a sweep file, read back from its attributes."""
    from ..model.scene import Scene

    return Scene(**{f.name: attrs[f"scene_{f.name}"] for f in dataclasses.fields(Scene) if f"scene_{f.name}" in attrs})


def _unit(unit: str) -> str:
    return "1" if unit == "dimensionless" else unit


def _attr(value):
    """A netCDF3 attribute value: a number or a string."""
    if isinstance(value, (bool, np.bool_)) or value is None:
        return str(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else str(value)
    return value if isinstance(value, str) else repr(value)
