"""palpate.bench: the benchmarks' figures as dicts."""

import json
import os
import tempfile

from . import _palpate
from .run import _scene


def feel(scene, device=None, duration=None):
    """``palpate bench feel`` of one scene: what a hand feels of it (steps, ripple, buzz, energy), as the --json
    file holds each scene. device: "scripted" (the scene's hand) or "replay:PATH"."""
    return json.loads(_palpate.bench_feel(_scene(scene).native, device or "", float(duration or 0.0)))


def model(references=("compression", "cantilever"), levels=(4, 5), young_modulus_Pa=1e5):
    """``palpate bench model``: each reference case's error against its closed form per lattice level, with what
    the level costs; returns the rows as the --json file holds them."""
    fd, path = tempfile.mkstemp(prefix="palpate_model_", suffix=".json")
    os.close(fd)
    try:
        _palpate.bench_model(list(references), [int(v) for v in levels], float(young_modulus_Pa), path)
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    finally:
        os.unlink(path)
