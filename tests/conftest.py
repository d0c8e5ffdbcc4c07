import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))  # tests/registry.py

import warnings

import pytest


@pytest.fixture(scope="module")
def quiet_compile():
    """camdyn's notices of a first compile or derivation silenced (a module uses it with
    ``pytestmark = pytest.mark.usefixtures("quiet_compile")``)."""
    import camdyn
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", camdyn.CompileNotice)
        yield
