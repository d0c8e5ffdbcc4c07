"""A run's switches as records (camdyn.engine.switches.Switches), read as Switch objects on demand.

The records are the engine's own (loop.SWITCH); what Switches adds is naming them and the array
operations a run joined from pieces and a stopped run need (shift, join, repeat, select).  Each
operation is checked against the same operation on the list of Switch objects: the two readings
must give the same switches exactly (they are the same float64 numbers, no arithmetic besides the
shifts, which are the same additions).
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import camdyn
from camdyn.engine.loop import SWITCH
from camdyn.engine.switches import Switch, Switches
from registry import RIG


@pytest.fixture(scope="module")
def run():
    """An impacting run with many switches of several surfaces (gap, gap rate, slip)."""
    scene = camdyn.Scene(damping="D", friction="coulomb")
    return camdyn.simulate(RIG.replace(l_lambda=0.016), scene, speed_rpm=1300, t_end=0.5)


def test_switches_read_as_switch_objects_by_index_and_by_iteration(run):
    sw = run.switches
    assert isinstance(sw, Switches) and len(sw) > 50
    listed = list(sw)
    assert all(isinstance(s, Switch) for s in listed)
    assert [sw[i] for i in range(len(sw))] == listed
    assert sw[-1] == listed[-1]
    assert list(sw[3:9]) == listed[3:9]
    assert len({s.surface for s in listed}) >= 2          # names come from the transition table
    np.testing.assert_array_equal(sw.t, [s.t for s in listed])
    assert all(sw.modes[b] == s.before and sw.modes[a] == s.after for b, a, s in zip(sw.before, sw.after, listed))


def test_shift_join_repeat_and_select_are_the_list_operations(run):
    sw = run.switches
    listed = list(sw)
    dt = 0.125
    assert list(sw.shifted(dt)) == [dataclasses.replace(s, t=s.t + dt) for s in listed]
    assert list(Switches.joined([sw[:10], sw[10:]])) == listed
    cycle = 0.05
    assert list(sw[:4].repeated(cycle, 3)) == [dataclasses.replace(s, t=s.t + m * cycle)
                                               for m in (1, 2, 3) for s in listed[:4]]
    late = sw[sw.t >= 0.25]
    assert list(late) == [s for s in listed if s.t >= 0.25]
    assert Switches.none().records.dtype == SWITCH and len(Switches.none()) == 0


def test_impacts_and_separations_are_the_contact_changes(run):
    contact = run.meta["contact"]
    listed = list(run.switches)
    impacts = [s.t for s in listed if not contact[s.before] and contact[s.after]]
    separations = [s.t for s in listed if contact[s.before] and not contact[s.after]]
    assert len(impacts) > 5
    np.testing.assert_array_equal(run.impacts(), impacts)
    np.testing.assert_array_equal(run.separations(), separations)
    later = run.after(0.25)
    assert list(later.switches) == [s for s in listed if s.t >= 0.25]


def test_records_of_another_dtype_are_refused():
    with pytest.raises(TypeError, match="SWITCH"):
        Switches(np.zeros(3), (), ())
