"""Where a sweep's finished points go, and the labelled Dataset they are assembled into.

A sweep with ``out="map.nc"`` streams into the folder ``map.nc.parts/`` as chunks finish:

``sweep.pickle``
    the :class:`~camdyn.sweep_spec.SweepSpec` (rig, scene, grid, measure, settings), for resume;
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
from pathlib import Path
from typing import Callable, Iterable

import numpy as np

from . import __version__
from .errors import CamdynError
from .rig import PARAMETERS
from .sweep_spec import ALL_CODES, NOT_RUN, OWN, ChunkResult, SweepSpec

FORMAT = "camdyn sweep folder 1"
PENDING = "not run yet: resume the sweep to run it"
log = logging.getLogger("camdyn.sweep")


class StoreError(CamdynError, ValueError):
    """A sweep folder cannot be created, found or read."""


def parts_folder(out) -> Path:
    """The folder a sweep writing ``out`` streams into: ``<out>.parts``."""
    return Path(os.fspath(out) + ".parts")


class MemoryStore:
    """Finished chunks kept in memory (a sweep without ``out``)."""

    def __init__(self):
        self._chunks: list[ChunkResult] = []

    def put(self, chunk: ChunkResult) -> None:
        self._chunks.append(chunk)

    def chunks(self) -> list[ChunkResult]:
        return list(self._chunks)


class FolderStore:
    """Finished chunks as files in ``<out>.parts/`` (see the module doc)."""

    def __init__(self, out):
        self.out = Path(out)
        self.folder = parts_folder(out)

    @classmethod
    def create(cls, out, spec: SweepSpec) -> "FolderStore":
        store = cls(out)
        if not store.out.parent.is_dir():
            raise StoreError(f"{store.out}: the folder {store.out.parent} does not exist")
        if store.folder.exists():
            raise StoreError(f"{store.folder} holds an unfinished sweep: resume it (camdyn.sweep.resume({str(out)!r}) "
                             f"or 'camdyn sweep --resume {out}'), or delete that folder to start again")
        (store.folder / "chunks").mkdir(parents=True)
        _atomic(store.folder / "sweep.pickle", lambda p: p.write_bytes(pickle.dumps(spec)))
        manifest = {"format": FORMAT, "out": str(out), "points": spec.size,
                    "grid": {k: v.tolist() for k, v in spec.axes.items()}, "attributes": attributes(spec)}
        _atomic(store.folder / "manifest.json", lambda p: p.write_text(json.dumps(manifest, indent=1) + "\n"))
        return store

    @classmethod
    def open(cls, out) -> "FolderStore":
        store = cls(out)
        if not (store.folder / "sweep.pickle").is_file():
            raise StoreError(f"{out}: no sweep to resume ({store.folder} does not hold one)")
        return store

    def spec(self) -> SweepSpec:
        manifest = json.loads((self.folder / "manifest.json").read_text())
        if manifest.get("format") != FORMAT:
            raise StoreError(f"{self.folder}: format {manifest.get('format')!r}, this camdyn reads {FORMAT!r}")
        written = manifest["attributes"].get("camdyn_version")
        if written != __version__:
            log.warning("%s was started by camdyn %s; this is camdyn %s", self.folder, written, __version__)
        try:
            return pickle.loads((self.folder / "sweep.pickle").read_bytes())
        except Exception as exc:
            raise StoreError(f"{self.folder}/sweep.pickle cannot be read ({type(exc).__name__}: {exc}); the measure "
                             "must be importable where the sweep is resumed (not defined in __main__)") from exc

    def put(self, chunk: ChunkResult) -> None:
        name = f"points-{int(chunk.index[0]):09d}-{int(chunk.index[-1]):09d}.nc"
        _atomic(self.folder / "chunks" / name, lambda p: chunk_dataset(chunk).to_netcdf(p, engine="scipy"))

    def chunks(self) -> list[ChunkResult]:
        import xarray as xr

        out = []
        for path in sorted((self.folder / "chunks").glob("points-*.nc")):
            try:
                ds = xr.load_dataset(path, engine="scipy")
                out.append(ChunkResult(ds["point_index"].values.astype(np.int64), ds["outcome"].values.astype(np.int32),
                                       [str(m) for m in ds["message"].values],
                                       {name: (v.dims[1:], v.values.astype(float)) for name, v in ds.data_vars.items()
                                        if name not in OWN}))
            except Exception as exc:  # a damaged file: its points run again
                log.warning("%s cannot be read (%s); its points will run again", path, exc)
                path.unlink()
        return out

    def finish(self, ds, complete: bool) -> None:
        """Write the Dataset to ``out``; remove the folder once every point has run."""
        _atomic(self.out, lambda p: ds.to_netcdf(p, engine="scipy"))
        if complete:
            shutil.rmtree(self.folder)


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
    attrs = {"title": "camdyn parameter sweep", "source": f"camdyn {__version__}", "camdyn_version": __version__,
             "grid": " ".join(spec.names), "points": spec.size, "scene": scene.slug}
    attrs.update({f"scene_{k}": v for k, v in dataclasses.asdict(scene).items()})
    attrs.update({"rig": rig.name, "rig_description": rig.description,
                  "rig_source": rig.origin or "not recorded (a Rig built in code)"})
    attrs.update({f"rig_{p.name}": getattr(rig, p.name) for p in PARAMETERS if getattr(rig, p.name) is not None})
    attrs["rig_units"] = ", ".join(f"{p.name} {_unit(p.unit)}" for p in PARAMETERS)
    attrs["measure"] = repr(spec.measure)
    if dataclasses.is_dataclass(spec.measure):
        attrs.update({f"measure_{f.name}": _attr(getattr(spec.measure, f.name))
                      for f in dataclasses.fields(spec.measure)})
    attrs.update({f"simulate_{k}": _attr(v) for k, v in sorted(spec.settings.items())})
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
    requested = spec.settings.get("revolutions")
    total = float(requested) * int(np.sum(ran)) if requested is not None else math.nan
    return {"revolutions_requested_total": total,
            "revolutions_run_total": float(np.nansum(ds["revolutions_run"].values)),
            "points_stopped_converged": int(np.sum(ds["stop_period"].values > 0))}


def rig_of(attrs: dict):
    """The base rig of a sweep file, read back from its attributes."""
    from .rig import Rig

    values = {p.name: attrs[f"rig_{p.name}"] for p in PARAMETERS if f"rig_{p.name}" in attrs}
    return Rig(**values, name=attrs.get("rig", "unnamed"), description=attrs.get("rig_description", ""))


def scene_of(attrs: dict):
    """The scene of a sweep file, read back from its attributes."""
    from .scene import Scene

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
