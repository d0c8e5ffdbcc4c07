"""The pieces of benchmarks/performance.py (docs/performance.md): what is measured (cases, peers,
precision, engine_costs, timing), the report's text (report) and its figures (figures).  Run the
whole with ``python benchmarks/performance.py``; these modules import ``floor`` and ``sweep_stop``
from benchmarks/, which that command puts on the path."""
