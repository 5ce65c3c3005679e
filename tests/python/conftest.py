"""Shared set-up of the Python module's tests: the repository's root, the palpate program, a small scene."""

import json
import os
import subprocess

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.environ.get("PALPATE_BIN_DIR", os.path.join(ROOT, "build", "bin"))


def scene_path(name):
    return os.path.join(ROOT, "scenes", name)


def palpate_cli(*args, check=True):
    """Runs the palpate program; returns the finished process (stdout and stderr as text)."""
    p = subprocess.run([os.path.join(BIN, "palpate"), *args], capture_output=True, text=True, cwd=ROOT, timeout=600)
    if check and p.returncode != 0:
        raise AssertionError(f"palpate {' '.join(args)} exited {p.returncode}: {p.stderr}")
    return p


@pytest.fixture
def small_scene():
    """cube_press made short: a 0.6 s press on a 6 cm box (level 4), the test's own copy as a dict."""
    with open(scene_path("cube_press.json"), encoding="utf-8") as f:
        data = json.load(f)
    data["duration_s"] = 0.6
    return data
