"""palpate.sweep: many recordings from one spec — a grid (or list) of scene overrides x models x modes — each run
on its own, locally on a process pool or on a Dask cluster, gathered into one table with a row per run.

A spec (a dict or a JSON file)::

    {
      "scene": "scenes/bunny_touch.json",           # the base scene (relative to the spec file)
      "models": ["a.ply", "b.stl"],                 # optional: each run's mesh.file (else the scene's)
      "modes": ["touch", "pull"],                   # optional: each run's interaction.mode (else the scene's)
      "grid": {"material.young_modulus_Pa": [1e5, 3e5]},   # every combination of these keys' values
      "list": [{"lattice.level": 4}, {"lattice.level": 5}], # or (and, after the grid) these override sets
      "duration_s": 1.0,                            # optional: each run's length (else the scene's)
      "frames": false                               # optional: render PNG frames (and keep them in the run's folder)
    }

Runs are independent recordings into <out>/runs/<run>/; each one that finishes leaves its row there (row.json), so a
sweep run again over the same folder skips them (resume). A run that fails is a row with its error. The table is
<out>/sweep.csv and, from Python, a pandas DataFrame.
"""

import argparse
import concurrent.futures as cf
import copy
import csv
import hashlib
import itertools
import json
import math
import multiprocessing
import os
import sys
import time

from . import _palpate

# the columns every row has, before its parameters and after them
LEAD = ["run", "model", "mode"]
TAIL = ["status", "error", "ticks", "contact_ticks", "max_force_N", "max_penetration_m", "state_hash", "frames",
        "wall_s", "out"]
# columns that differ between two runs of the same sweep (the machine's timing); left out when tables are compared
TIMING = ["wall_s"]


def load_spec(spec):
    """The spec as a dict, its paths made absolute (relative to the spec file, or to the working folder)."""
    base = os.getcwd()
    if not isinstance(spec, dict):
        path = os.fspath(spec)
        try:
            with open(path, encoding="utf-8") as f:
                spec = json.load(f)
        except (OSError, ValueError) as e:
            raise _palpate.SceneError(f"sweep spec '{path}': {e}") from e
        base = os.path.dirname(os.path.abspath(path))
    spec = copy.deepcopy(spec)
    known = {"scene", "models", "modes", "grid", "list", "duration_s", "frames"}
    unknown = sorted(set(spec) - known)
    if unknown:
        raise _palpate.SceneError(f"sweep spec: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(known))})")
    if "scene" not in spec:
        raise _palpate.SceneError("sweep spec: 'scene' (the base scene's file) is required")
    spec["scene"] = os.path.join(base, spec["scene"])
    spec["models"] = [os.path.join(base, m) for m in spec.get("models", [])]
    for key in ("grid",):
        for k, values in spec.get(key, {}).items():
            if not isinstance(values, list) or not values:
                raise _palpate.SceneError(f"sweep spec: grid '{k}' must be a non-empty list of values")
    return spec


def expand(spec):
    """Every run of the spec, in a fixed order: a dict of its model, mode and overrides, and its name."""
    grid = spec.get("grid", {})
    keys = sorted(grid)
    sets = [dict(zip(keys, values)) for values in itertools.product(*(grid[k] for k in keys))] if keys else []
    sets += [dict(s) for s in spec.get("list", [])]
    if not sets:
        sets = [{}]
    runs = []
    for model in spec["models"] or [None]:
        for mode in spec.get("modes") or [None]:
            for overrides in sets:
                params = {"model": model, "mode": mode, "overrides": overrides}
                digest = hashlib.sha1(json.dumps(params, sort_keys=True).encode()).hexdigest()[:8]
                runs.append(dict(params, run=f"{len(runs):04d}_{digest}"))
    return runs


def run_one(spec, task, out):
    """Records one run of the sweep and returns its row (never raises for a failed run: its row holds the error)."""
    from .run import record
    from .scene import Scene

    row = {"run": task["run"], "model": task["model"] or "", "mode": task["mode"] or ""}
    row.update(task["overrides"])
    run_dir = os.path.join(out, "runs", task["run"]) if out else None
    t0 = time.monotonic()
    try:
        overrides = dict(task["overrides"])
        if task["model"]:
            overrides["mesh.file"] = task["model"]
        if task["mode"]:
            overrides["interaction.mode"] = task["mode"]
        scene = Scene(spec["scene"], overrides)
        rec = record(scene, out=run_dir, frames=spec.get("frames", False), duration=spec.get("duration_s"))
        log = rec.log
        force = [math.sqrt(x * x + y * y + z * z) for x, y, z in zip(log["force_x_N"], log["force_y_N"], log["force_z_N"])]
        depth = [((px - tx) ** 2 + (py - ty) ** 2 + (pz - tz) ** 2) ** 0.5 if c > 0 else 0.0
                 for px, py, pz, tx, ty, tz, c in zip(log["proxy_x_m"], log["proxy_y_m"], log["proxy_z_m"],
                                                      log["tool_x_m"], log["tool_y_m"], log["tool_z_m"], log["contact"])]
        row.update(status="ok", error="", ticks=len(force), contact_ticks=int(sum(c > 0 for c in log["contact"])),
                   max_force_N=max(force, default=0.0), max_penetration_m=max(depth, default=0.0),
                   state_hash=rec.state_hash, frames=rec.frames_written)
    except KeyboardInterrupt:
        raise
    except Exception as e:  # a failed run is a row, never the end of the sweep
        row.update(status="failed", error=str(e), ticks=0, contact_ticks=0, max_force_N=float("nan"),
                   max_penetration_m=float("nan"), state_hash="", frames=0)
    row.update(wall_s=round(time.monotonic() - t0, 3), out=run_dir or "")
    if run_dir and row["status"] == "ok":
        _write_json(os.path.join(run_dir, "row.json"), row)
    return row


def _write_json(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".partial"
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(data, f)
    os.replace(tmp, path)


def _finished_row(out, task):
    """The row a finished run left in its folder (resume), or None."""
    if not out:
        return None
    try:
        with open(os.path.join(out, "runs", task["run"], "row.json"), encoding="utf-8") as f:
            row = json.load(f)
        return row if row.get("run") == task["run"] and row.get("status") == "ok" else None
    except (OSError, ValueError):
        return None


def _columns(rows, tasks):
    keys = []
    for t in tasks:
        for k in t["overrides"]:
            if k not in keys:
                keys.append(k)
    return LEAD + keys + TAIL


def write_table(path, rows, columns):
    """The table as CSV, written whole or not at all (a temporary name, then renamed)."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    tmp = path + ".partial"
    with open(tmp, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    os.replace(tmp, path)


def sweep(spec, out=None, scheduler=None, workers=None, progress=True):
    """Runs every run of ``spec`` (a dict or a JSON file; see the module's doc) and returns the table as a pandas
    DataFrame, one row per run in the spec's order.

    out: the sweep's folder (runs/<run>/ and sweep.csv); runs whose row is already there are skipped. None: every run
    in a temporary folder, nothing kept but the table. scheduler: a Dask scheduler's address ("tcp://host:8786"), or
    a dask.distributed Client or cluster; None: a local process pool of ``workers`` processes (the cores).
    progress: a line on stderr as each run finishes.
    """
    import pandas as pd

    spec = load_spec(spec)
    tasks = expand(spec)
    out = os.path.abspath(out) if out else None
    rows = {}
    todo = []
    for t in tasks:
        done = _finished_row(out, t)
        if done is not None:
            rows[t["run"]] = done
        else:
            todo.append(t)
    if progress and rows:
        print(f"sweep: {len(rows)} of {len(tasks)} runs already finished in {out}: skipped", file=sys.stderr)

    def finished(row):
        rows[row["run"]] = row
        if progress:
            failed = sum(r["status"] != "ok" for r in rows.values())
            note = f"failed: {row['error']}" if row["status"] != "ok" else f"max force {row['max_force_N']:.3f} N"
            print(f"sweep: {len(rows)}/{len(tasks)} runs done ({failed} failed); {row['run']} {note}",
                  file=sys.stderr, flush=True)

    if todo and scheduler is not None:
        _run_on_dask(spec, todo, out, scheduler, finished)
    elif todo:
        n = workers or os.cpu_count() or 1
        if n == 1:
            for t in todo:
                finished(run_one(spec, t, out))
        else:
            # fork: a script without a __main__ guard works (spawn would run it again in each worker); the module
            # runs no thread of its own between recordings, so none is forked
            ctx = multiprocessing.get_context("fork")
            with cf.ProcessPoolExecutor(max_workers=n, mp_context=ctx) as pool:
                futures = [pool.submit(run_one, spec, t, out) for t in todo]
                for f in cf.as_completed(futures):
                    finished(f.result())
    ordered = [rows[t["run"]] for t in tasks]
    columns = _columns(ordered, tasks)
    if out:
        write_table(os.path.join(out, "sweep.csv"), ordered, columns)
    return pd.DataFrame(ordered, columns=columns)


def _run_on_dask(spec, todo, out, scheduler, finished):
    from dask.distributed import Client, as_completed

    own = isinstance(scheduler, str)
    client = Client(scheduler) if own else (scheduler if isinstance(scheduler, Client) else Client(scheduler))
    try:
        futures = [client.submit(run_one, spec, t, out, pure=False, key=f"palpate-{t['run']}-{time.time_ns()}")
                   for t in todo]
        for f in as_completed(futures):
            finished(f.result())
    finally:
        if own or not isinstance(scheduler, Client):
            client.close()


def main(argv=None):
    p = argparse.ArgumentParser(prog="palpate sweep", description=(
        "Runs a sweep: a grid (or list) of scene overrides x models x modes, each an independent recording, "
        "gathered into one table (OUT/sweep.csv). Finished runs in OUT are skipped."))
    p.add_argument("spec", help="the sweep's JSON spec (see docs/python.md)")
    p.add_argument("--out", default=None, help="the sweep's folder (default: out/sweep_<spec name>)")
    p.add_argument("--scheduler", default=None, help="a Dask scheduler's address (tcp://HOST:8786); default: local")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: the cores)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    a = p.parse_args(argv)
    out = a.out or os.path.join("out", "sweep_" + os.path.splitext(os.path.basename(a.spec))[0])
    try:
        table = sweep(a.spec, out=out, scheduler=a.scheduler, workers=a.workers, progress=not a.quiet)
    except (_palpate.SceneError, _palpate.RunError, OSError) as e:
        print(f"palpate: sweep: {e}", file=sys.stderr)
        return 1
    failed = int((table["status"] != "ok").sum())
    print(f"table    {os.path.join(out, 'sweep.csv')} ({len(table)} runs, {failed} failed)")
    return 1 if failed else 0

