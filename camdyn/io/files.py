"""A run on disk: time histories to CSV and NetCDF, and one quantity read back.

* :func:`write_csv`: one column per quantity with its unit in the header (``alpha (rad)``),
  and the regime's name;
* :func:`write_netcdf`: the same as NetCDF-3 (through SciPy) with ``units`` and ``long_name``
  on every variable, the regime as integer codes (``flag_values``/``flag_meanings``), the
  impact times, and the global attributes of :func:`camdyn.io.metadata.run_attributes`;
* :func:`read_series`: ``(t, values, period)`` of one quantity from either file;
* :func:`check_suffix`: the file kinds by name (``.csv``, ``.nc``), checked before any work.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..errors import CamdynError
from .metadata import column_header, parse_column_header, run_attributes, variable_attributes

__all__ = ["SUFFIXES", "FileFormatError", "check_suffix", "write_csv", "write_netcdf", "read_series"]

#: accepted file name endings of each kind of file (the first is the default)
SUFFIXES = {"csv": (".csv", ".txt"), "netcdf": (".nc", ".cdf", ".netcdf")}
_NAMES = {"csv": "a CSV file", "netcdf": "a NetCDF file"}
_NETCDF3_MAGIC, _HDF5_MAGIC = b"CDF", b"\x89HDF"


class FileFormatError(CamdynError, ValueError):
    """A file's name or content is not of the kind asked for (a CSV, a NetCDF-3 file...)."""


def check_suffix(path: str | Path, kind: str) -> str:
    """``path`` if its ending suits ``kind`` ("csv" or "netcdf"); with no ending, the default
    one is added; another ending raises :class:`FileFormatError`."""
    p = Path(path)
    valid = SUFFIXES[kind]
    if not p.suffix:
        return str(p) + valid[0]
    if p.suffix.lower() not in valid:
        other = next((k for k, v in SUFFIXES.items() if p.suffix.lower() in v), None)
        raise FileFormatError(f"{path}: {_NAMES[kind]} name ends in {' or '.join(valid)}"
                              + (f" ({p.suffix} is {_NAMES[other]})" if other else ""))
    return str(path)


def _columns(result) -> list[str]:
    """The time histories of a Result, its follower's state under their names (alpha or y)."""
    q = result.meta.get("coordinate", "alpha")
    return ["t", q, f"{q}_dot", "Theta", f"{q}_r"] + list(result.outputs)


def write_csv(result, path: str | Path) -> None:
    """Time histories as CSV: one column per quantity, SI units in the headers, and the regime."""
    columns = _columns(result)
    data = [getattr(result, c) for c in columns]
    with open(path, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow([column_header(c) for c in columns] + ["regime"])
        for i in range(result.t.size):
            writer.writerow([repr(float(col[i])) for col in data] + [result.regime[i]])


def write_netcdf(result, path: str | Path, rig=None, *, rig_source: str | None = None, settings=None,
                 attrs: dict | None = None) -> None:
    """Time histories as NetCDF-3, self-describing (see the module doc).

    ``rig``, ``rig_source`` and ``settings`` go to :func:`camdyn.io.metadata.run_attributes`
    (the file then holds what is needed to run it again: :func:`camdyn.io.metadata.from_attributes`);
    ``attrs`` are added to the global attributes.
    """
    import xarray as xr

    regimes = sorted(set(result.regime.tolist()))
    codes = np.array([regimes.index(r) for r in result.regime], dtype=np.int8)
    data = {c: ("t", np.asarray(getattr(result, c), dtype=float), variable_attributes(c))
            for c in _columns(result) if c != "t"}
    data["regime"] = ("t", codes, {"long_name": variable_attributes("regime")["long_name"],
                                   "flag_values": np.arange(len(regimes), dtype=np.int8),
                                   "flag_meanings": " ".join(regimes)})
    data["impact_t"] = ("impact", np.asarray(result.impacts(), dtype=float),
                        {"units": "s", "long_name": "times at which the follower hits the cam"})
    meta = {**run_attributes(result, rig, rig_source=rig_source, settings=settings), **(attrs or {})}
    ds = xr.Dataset(data, coords={"t": ("t", np.asarray(result.t, dtype=float), variable_attributes("t"))},
                    attrs=meta)
    ds.to_netcdf(path, engine="scipy")


def _read_netcdf(p: Path, quantity: str):
    import xarray as xr

    with open(p, "rb") as fh:
        magic = fh.read(4)
    if magic.startswith(_HDF5_MAGIC):
        raise FileFormatError(f"{p}: a NetCDF-4 (HDF5) file; camdyn reads NetCDF-3, as 'camdyn simulate "
                              "--netcdf' writes it")
    if not magic.startswith(_NETCDF3_MAGIC):
        raise FileFormatError(f"{p}: not a NetCDF file (written by 'camdyn simulate --netcdf')")
    with xr.open_dataset(p, engine="scipy") as ds:
        if quantity not in ds and quantity != "t":
            raise FileFormatError(f"{p}: no variable {quantity!r} (has {', '.join(map(str, ds.data_vars))})")
        t, x = ds["t"].values.astype(float), ds[quantity].values.astype(float)
        period = float(ds.attrs.get("period_s", -1.0))
        theta = ds["Theta"].values.astype(float) if "Theta" in ds else None
    return t, x, theta, period


def _read_csv(p: Path, quantity: str):
    try:
        with open(p, newline="", encoding="utf-8") as fh:
            header = next(csv.reader(fh), None)
    except UnicodeDecodeError:
        raise FileFormatError(f"{p}: not a text file; a CSV from 'camdyn simulate --csv' is needed") from None
    names = [parse_column_header(h) for h in header or []]
    if "t" not in names or quantity not in names:
        raise FileFormatError(f"{p}: a CSV from 'camdyn simulate --csv' with columns t and {quantity} is needed"
                              + (f" (has {', '.join(names)})" if names else ""))
    wanted = [c for c in ("t", quantity, "Theta") if c in names]
    table = np.atleast_2d(np.genfromtxt(p, delimiter=",", skip_header=1, usecols=[names.index(c) for c in wanted]))
    theta = table[:, 2] if table.shape[1] > 2 else None
    return table[:, 0], table[:, 1], theta, -1.0


def read_series(path: str | Path, quantity: str):
    """``(t, values, period)`` of one quantity of a run saved by :func:`write_csv` or
    :func:`write_netcdf` (period in s; ``inf`` when the cam has none; from ``Theta(t)`` for a CSV
    at constant speed).  A missing file, a wrong kind of file or a missing quantity raise
    :class:`FileFormatError` (or ``FileNotFoundError``)."""
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(2, "no such file", str(path))
    suffix = p.suffix.lower()
    if suffix in SUFFIXES["netcdf"]:
        t, x, theta, period = _read_netcdf(p, quantity)
    elif suffix in SUFFIXES["csv"]:
        t, x, theta, period = _read_csv(p, quantity)
    else:
        raise FileFormatError(f"{path}: a saved run is a .csv or .nc file (written by 'camdyn simulate')")
    if not period > 0 and theta is not None and t.size > 1:  # constant speed: Theta is linear in t
        rate = (theta[-1] - theta[0]) / (t[-1] - t[0])
        if rate != 0 and np.allclose(theta, theta[0] + rate * (t - t[0]), rtol=0,
                                     atol=1e-9 * max(1, abs(theta).max())):
            period = abs(2 * math.pi / rate)
    return t, x, (period if period > 0 else math.inf)
