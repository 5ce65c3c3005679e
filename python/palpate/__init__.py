"""Palpate from Python.

Scenes checked as the command line checks them (palpate.Scene), recordings whose haptic log comes back as numpy
arrays (palpate.record), a session stepped tick by tick or frame by frame (palpate.Session), the benchmarks'
figures as dicts (palpate.bench) and sweeps of recordings run locally or on a Dask cluster (palpate.sweep).
"""

from ._palpate import RunError, SceneError, haptic_log_columns
from .scene import Scene
from .run import Recording, Session, record
from . import bench
from .sweep import sweep

__all__ = ["Scene", "Session", "Recording", "record", "bench", "sweep", "SceneError", "RunError",
           "haptic_log_columns"]
