"""palpate.sweep and `palpate sweep`: a grid x models run serially, on a local pool and on a Dask LocalCluster of two
workers gives one table; a failed run is a row; a sweep run again over its folder skips what finished."""

import json
import os

import pandas as pd
import pytest

import palpate
from palpate.sweep import TIMING
from conftest import palpate_cli

MODELS = ["/usr/share/assimp/models/PLY/Wuson.ply", "/usr/share/assimp/models/STL/Spider_ascii.stl"]


def spec(tmp_path):
    """A 0.6 s press 6 mm into any model (the keys placed on the model's box and surface): 3 moduli x 3 region sizes
    x 2 models."""
    scene = {
        "mesh": {"file": MODELS[0], "size_m": 0.06},
        "grid": {"levels": 5},
        "lattice": {"level": 4, "radius_cells": 2, "integrator": "implicit_euler", "fix_floor": True,
                    "gravity_m_per_s2": [0, 0, 0]},
        "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25, "density_kg_per_m3": 1070},
        "device": {"driver": "scripted", "max_force_N": 3.3, "coupling_N_per_m": 300},
        "interaction": {"mode": "touch"},
        "trajectory": [{"t_s": 0.0, "pos_rel": [0.5, 0.5, 1.3]},
                       {"t_s": 0.5, "pos_rel": [0.5, 0.5, 0.5], "surface": True, "depth_m": 0.006}],
        "duration_s": 0.6,
    }
    (tmp_path / "press.json").write_text(json.dumps(scene))
    s = {"scene": "press.json", "models": MODELS,
         "grid": {"material.young_modulus_Pa": [5e4, 1e5, 3e5], "lattice.radius_cells": [1, 2, 3]}, "list": []}
    (tmp_path / "sweep.json").write_text(json.dumps(s))
    return tmp_path / "sweep.json"


def same(a, b):
    cols = [c for c in a.columns if c not in TIMING + ["out"]]
    pd.testing.assert_frame_equal(a[cols].reset_index(drop=True), b[cols].reset_index(drop=True))


@pytest.mark.skipif(not all(os.path.exists(m) for m in MODELS), reason="assimp-testmodels missing")
def test_a_sweep_on_a_dask_cluster_equals_the_serial_one(tmp_path):
    from dask.distributed import Client, LocalCluster

    path = spec(tmp_path)
    serial = palpate.sweep(str(path), workers=1, progress=False)
    assert len(serial) == 18
    assert list(serial["status"]) == ["ok"] * 18, serial["error"].tolist()
    assert serial["max_force_N"].min() > 0.1  # every press reached its model
    assert serial["contact_ticks"].min() > 50
    assert serial["model"].tolist() == [MODELS[0]] * 9 + [MODELS[1]] * 9
    # stiffer presses the same depth harder, on each model and region
    for (m, r), rows in serial.groupby(["model", "lattice.radius_cells"]):
        f = rows.sort_values("material.young_modulus_Pa")["max_force_N"].tolist()
        assert f[0] < f[2], (m, r, f)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        on_dask = palpate.sweep(str(path), out=tmp_path / "dask", scheduler=client, progress=False)
        # the command line on the same cluster, by its address
        cli = palpate_cli("sweep", str(path), "--out", str(tmp_path / "cli"), "--scheduler",
                          cluster.scheduler_address, "-q")
    same(serial, on_dask)
    assert "(18 runs, 0 failed)" in cli.stdout
    text = {c: str for c in ("run", "model", "mode", "status", "error", "state_hash", "out")}
    same(serial, pd.read_csv(tmp_path / "cli" / "sweep.csv", keep_default_na=False, dtype=text))
    table = pd.read_csv(tmp_path / "dask" / "sweep.csv")
    assert len(table) == 18 and (tmp_path / "dask" / "runs").is_dir()


@pytest.mark.skipif(not all(os.path.exists(m) for m in MODELS), reason="assimp-testmodels missing")
def test_a_failed_run_is_a_row_and_a_second_sweep_resumes(tmp_path, capfd):
    path = spec(tmp_path)
    s = json.loads(path.read_text())
    s["models"] = MODELS[:1]
    s["grid"] = {"material.young_modulus_Pa": [1e5, -1.0]}  # the second is refused by the scene's checks
    path.write_text(json.dumps(s))
    out = tmp_path / "out"
    first = palpate.sweep(str(path), out=out, workers=2)
    assert first["status"].tolist() == ["ok", "failed"]
    assert "material.young_modulus_Pa" in first["error"][1]
    assert "2/2 runs done (1 failed)" in capfd.readouterr().err
    again = palpate_cli("sweep", str(path), "--out", str(out), check=False)
    assert again.returncode == 1  # a failed run fails the command
    assert "1 of 2 runs already finished" in again.stderr
    assert "(2 runs, 1 failed)" in again.stdout
    second = pd.read_csv(out / "sweep.csv")
    assert second["state_hash"][0] == first["state_hash"][0]
    assert second["wall_s"][0] == first["wall_s"][0]  # the finished run's row, kept, not run again


def test_a_bad_spec_is_one_line(tmp_path):
    (tmp_path / "s.json").write_text(json.dumps({"scene": "x.json", "grids": {}}))
    p = palpate_cli("sweep", str(tmp_path / "s.json"), check=False)
    assert p.returncode == 1
    assert p.stderr.strip() == "palpate: sweep: sweep spec: unknown key(s) grids (known: " \
        "duration_s, frames, grid, list, models, modes, scene)"
