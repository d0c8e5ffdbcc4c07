"""One source, two ways to run it: the engine's functions are plain Python and compiled code.

A function decorated with :func:`jitable` runs as ordinary Python when Python calls it (with
Python kernels: a user's cam motion, debugging) and is compiled into its caller when compiled
code calls it (numba's ``register_jitable``), with IEEE arithmetic (a division by zero gives
inf or nan, as in NumPy, instead of raising).  So the hybrid rules, the stepper and the loop
exist once, whatever runs them.

Only compiled code calls the compiled versions, so they are built without the C wrapper numba
otherwise gives every function it compiles (``no_cfunc_wrapper``): one wrapper less per
function on a cold start (docs/performance.md, Start-up).

The arrays a compiled :func:`jitable` function receives are borrowed from its caller, which
holds them for the call: it is compiled without numba's reference counting (NRT), which would
otherwise increment and decrement, atomically, the count of every array it is passed, on
entry and exit of every call (on the sliding benchmark, benchmarks/floor.py, some 60 atomic
operations per step, 5 % of the engine's time).  Such a function may read, write and slice
the arrays it is given, but not create an array (numba refuses to compile that without NRT)
nor return one.  A function that creates arrays, or returns one, is :func:`allocating`.
"""
from __future__ import annotations

from numba.extending import register_jitable


def jitable(fn):
    """Mark an engine function: Python when called from Python, compiled when called from numba
    (without reference counting: it must not create nor return an array)."""
    return register_jitable(error_model="numpy", no_cfunc_wrapper=True, _nrt=False)(fn)


def allocating(fn):
    """:func:`jitable` for a function that creates arrays or returns one (compiled with NRT)."""
    return register_jitable(error_model="numpy", no_cfunc_wrapper=True)(fn)
