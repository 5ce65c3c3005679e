"""palpate.record (one recording, its log as numpy arrays) and palpate.Session (a run stepped from Python)."""

import json
import shutil
import tempfile
import warnings

import numpy as np

from . import _palpate
from .scene import Scene


def _scene(scene):
    return scene if isinstance(scene, Scene) else Scene(scene)


class Recording:
    """What a recording left.

    ``summary``: summary.json as a dict. ``log``: haptic.csv's columns (``palpate.haptic_log_columns``), each a
    float64 numpy array with one row per servo tick, taken from memory as the rows were logged. ``state_hash``: the
    lockstep state hash (empty for realtime). ``out``: the output folder, or None when the recording was made in a
    temporary one (``record(out=None)``), which is gone. ``interrupted``: why the run ended early, else empty.
    """

    def __init__(self, raw, out):
        self.summary = json.loads(raw["summary_json"])
        self.log = raw["log"]
        self.state_hash = raw["state_hash"]
        self.frames_written = raw["frames_written"]
        self.video = raw["video_path"] or None
        self.out = out
        self.interrupted = raw["interrupted"]

    def log_array(self):
        """The log as one (ticks x columns) float64 array, columns in ``palpate.haptic_log_columns``' order."""
        return np.column_stack([self.log[c] for c in _palpate.haptic_log_columns.split(",")])

    def log_frame(self):
        """The log as a pandas DataFrame (pandas imported on first use)."""
        import pandas as pd
        return pd.DataFrame(self.log)

    def __repr__(self):
        return f"Recording({self.summary.get('scene', '')!r}, {len(self.log['tick'])} ticks, hash {self.state_hash!r})"


def record(scene, out=None, mode=None, frames=False, video=False, duration=None, device=None, quiet=True):
    """Records ``scene`` (a Scene, a path or a dict) as ``palpate record`` does and returns a Recording.

    out: the output folder (None: a temporary one, removed after; the summary and the log come back all the same).
    mode: "lockstep" or "realtime" (None: the scene's). frames: render PNG frames (as --no-render when False);
    video: also the MP4 (needs frames). duration: scene seconds (None: the scene's). device: as --device (None: the
    scene's driver). quiet: no progress line. The run releases the GIL; Ctrl-C stops it with every output whole and
    raises KeyboardInterrupt. A refused scene raises SceneError, a failed run RunError, both with the command line's
    message.
    """
    scene = _scene(scene)
    tmp = tempfile.mkdtemp(prefix="palpate_") if out is None else None
    try:
        raw = _palpate.record(scene.native, tmp or str(out), mode or "", bool(frames), bool(video),
                              float(duration or 0.0), device or "", bool(quiet))
    finally:
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)
    for w in raw["warnings"]:
        warnings.warn(w, RuntimeWarning, stacklevel=2)
    rec = Recording(raw, None if tmp else str(out))
    if raw["diverged"] > 0 and not scene.data.get("lattice", {}).get("allow_divergence", False):
        raise _palpate.RunError(
            f"scene '{scene.path}': the lattice diverged {raw['diverged']} time(s) (each reset it to rest); "
            f"lattice.allow_divergence accepts it" + (f" (see {raw['summary_path']})" if not tmp else ""))
    return rec


class Session(_palpate.NativeSession):
    """One run stepped from Python on the lockstep clock ``palpate record`` uses.

    ``Session(scene)`` plays the scene's own device (its scripted hand); ``Session(scene, device="python")`` is held
    where ``set_pose`` puts it. ``tick()`` runs one servo tick (and the frames due before it), ``step(frames=1)`` one
    frame period of ticks, ``run(duration=None)`` the rest of the scene as ``palpate record`` runs it (after which
    ``state_hash`` equals the recording's). Read ``force``, ``proxy``, ``tool`` (numpy copies, metres and newtons),
    ``contact`` ("free", "touch", "grab", "cut"), ``nodes`` / ``rest_nodes`` (the lattice's, (n, 3) copies, None
    before a contact builds it), ``vertices`` (the deformed mesh, (n, 3) copy) and ``samples()`` (the log's columns
    of the ticks since the last call, as record's ``log``). Steps release the GIL.
    """

    def __init__(self, scene, device=None):
        self.scene = _scene(scene)
        super().__init__(self.scene.native, device or "")

    def run(self, duration=None):
        super().run(float(duration or 0.0))

    def set_pose(self, pos_m, buttons=0):
        """Puts the handle at pos_m (x, y, z in metres); buttons: bit 0 is the main button (True for pressed)."""
        super().set_pose([float(v) for v in pos_m], int(buttons))
