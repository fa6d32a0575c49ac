"""Shared fixtures: paths of the repository, the `paperbsdf` command, Mitsuba variants."""

from __future__ import annotations

import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
TOOLS = os.path.join(os.path.dirname(HERE), "tools")
sys.path.insert(0, TOOLS)

import _common  # noqa: E402

REPO = _common.REPO
SHARED = os.path.join(REPO, "data")  # holds reference/: the bundled reference data


@pytest.fixture(scope="session")
def cli() -> str:
    """The `paperbsdf` command (see tools/_common.py: $PAPERBSDF_CLI, the workspace's binary, or built)."""
    return _common.paperbsdf_cli()


@pytest.fixture(scope="session")
def repo() -> str:
    return REPO


@pytest.fixture(scope="session")
def shared() -> str:
    return SHARED


def mitsuba(variant: str):
    """Mitsuba in `variant` with the plugin registered."""
    return _common.setup_mitsuba(variant)
