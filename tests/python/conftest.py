"""Shared fixtures of the Python tests: the source tree and a case path."""
import os

import pytest

SOURCE = os.environ.get("PX_SOURCE_DIR") or os.path.abspath(
    os.path.join(os.path.dirname(__file__), "..", ".."))


def case_path(name):
    return os.path.join(SOURCE, "cases", name)


@pytest.fixture
def source():
    return SOURCE
