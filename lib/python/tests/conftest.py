"""Shared fixtures of the package's tests: a context, the C reference program, a scratch
directory (ctest sets FCM_PY_REFERENCE, FCM_PY_SCRATCH and FCM_SOURCE_DIR)."""

import os
import pathlib

import pytest

import fcm


@pytest.fixture
def ctx():
    c = fcm.Context()
    yield c
    c.close()


@pytest.fixture
def reference():
    path = os.environ.get("FCM_PY_REFERENCE")
    if not path:
        pytest.skip("FCM_PY_REFERENCE (the C reference program) is not set: run through ctest")
    return path


@pytest.fixture
def source_dir():
    return pathlib.Path(os.environ.get("FCM_SOURCE_DIR",
                                       pathlib.Path(__file__).resolve().parents[3]))


@pytest.fixture
def scratch(tmp_path):
    return tmp_path
