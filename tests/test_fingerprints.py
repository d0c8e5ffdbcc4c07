"""Runs are the same, bit for bit, as when tests/data/run_fingerprints.json was written (before
the code was rearranged into subpackages, issue 26): the benchmark scenes at three tolerances
with both step-size controllers, the hard cases, a tangent run, the python backend.

A change that is meant to change runs (a new rule, another controller) rewrites the file with
``python tests/fingerprints.py`` and says so in its commit.
"""
from __future__ import annotations

import json

import pytest

from fingerprints import PATH, fingerprints

EXPECTED = json.loads(PATH.read_text())


@pytest.fixture(scope="module")
def now():
    return fingerprints()


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_a_run_is_unchanged_to_the_bit(now, name):
    got, expected = now[name], EXPECTED[name]
    assert got["outcome"] == expected["outcome"] and got["switches"] == expected["switches"], (got, expected)
    assert got["sha256"] == expected["sha256"], f"{name}: end {got['end']} against {expected['end']}"
