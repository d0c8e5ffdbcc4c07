"""One source, two ways to run it: the engine's functions are plain Python and compiled code.

A function decorated with :func:`jitable` runs as ordinary Python when Python calls it (with
Python kernels: a user's cam motion, debugging) and is compiled into its caller when compiled
code calls it (numba's ``register_jitable``), with IEEE arithmetic (a division by zero gives
inf or nan, as in NumPy, instead of raising).  So the hybrid rules, the stepper and the loop
exist once, whatever runs them.

Only compiled code calls the compiled versions, so they are built without the C wrapper numba
otherwise gives every function it compiles (``no_cfunc_wrapper``): one wrapper less per
function on a cold start (docs/performance.md, Start-up).
"""
from __future__ import annotations

from numba.extending import register_jitable


def jitable(fn):
    """Mark an engine function: Python when called from Python, compiled when called from numba."""
    return register_jitable(error_model="numpy", no_cfunc_wrapper=True)(fn)
