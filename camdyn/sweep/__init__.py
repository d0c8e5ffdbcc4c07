"""Parameter sweeps on any concurrent.futures.Executor: the API (api), what a sweep runs (spec),
its checks before any work (check), running its chunks (dispatch) and storing them (store); basin
maps of initial conditions as sweeps (attractors)."""
from __future__ import annotations

from .._lazy import lazy

#: public name -> the module (relative to this package) that defines it; loaded on first use
_EXPORTS = {
    'ALL_CODES': '.api',
    'attractor_table': '.attractors',
    'basins': '.attractors',
    'InvalidGridError': '.api',
    'NotASweepError': '.api',
    'PoincareSection': '.api',
    'StopWhenPeriodic': '.api',
    'StoreError': '.api',
    'Summary': '.api',
    'bifurcation': '.api',
    'check_out': '.api',
    'contact_loss_map': '.api',
    'load_partial': '.api',
    'load_sweep': '.api',
    'parts_folder': '.api',
    'process_pool': '.api',
    'refuse_if_in_use': '.api',
    'resume': '.api',
    'rig_of': '.api',
    'scene_of': '.api',
    'settings_of': '.api',
    'stop_summary': '.api',
    'sweep': '.api',
}

__getattr__, __dir__ = lazy(__name__, _EXPORTS)
__all__ = sorted(_EXPORTS)
