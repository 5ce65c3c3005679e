"""palpate.record and palpate.Session: the log as numpy arrays equal to haptic.csv, the command line's state hash,
a session stepped from Python, Ctrl-C keeping every output whole."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import palpate
from conftest import ROOT, palpate_cli, scene_path


def test_the_log_is_haptic_csv_as_float64_arrays(tmp_path, small_scene):
    rec = palpate.record(small_scene, out=tmp_path / "run")
    columns = palpate.haptic_log_columns.split(",")
    assert list(rec.log) == columns
    ticks = rec.summary["servo_ticks"]
    assert ticks == 600
    for c in columns:
        assert rec.log[c].dtype == np.float64 and rec.log[c].shape == (ticks,)
    csv = np.loadtxt(tmp_path / "run" / "haptic.csv", delimiter=",", skiprows=1)
    assert csv.shape == (ticks, len(columns))
    np.testing.assert_allclose(rec.log_array(), csv, rtol=1e-6, atol=1e-9)
    force = np.linalg.norm(rec.log_array()[:, 8:11], axis=1)
    assert force.max() == pytest.approx(rec.summary["max_force_N"], rel=1e-6)
    assert force.max() > 0.1  # the press reached the box
    assert rec.out == str(tmp_path / "run") and rec.frames_written == 0


def test_without_a_folder_nothing_is_left_and_the_hash_is_the_command_lines(tmp_path, small_scene):
    path = tmp_path / "press.json"
    path.write_text(json.dumps(small_scene))
    rec = palpate.record(str(path))
    assert rec.out is None
    cli = palpate_cli("record", str(path), "--no-render", "-q", "--out", str(tmp_path / "cli"))
    assert f"state_hash {rec.state_hash}" in cli.stdout
    assert len(rec.state_hash) == 16


def test_frames_are_rendered_when_asked(tmp_path, small_scene):
    small_scene["duration_s"] = 0.2
    rec = palpate.record(small_scene, out=tmp_path / "f", frames=True)
    assert rec.frames_written == 12
    assert len(list((tmp_path / "f" / "frames").glob("frame_*.png"))) == 12


def test_a_stepped_session_reaches_the_recordings_hash(small_scene):
    rec = palpate.record(small_scene)
    s = palpate.Session(small_scene)
    s.step()
    assert s.frames == 1 and s.ticks == 17  # frame 0, then the ticks before frame 1 (at 16.7 ms)
    while s.ticks < 300:
        s.tick()
    assert s.contact == "touch"
    assert s.force[2] > 0.0  # the box pushes the tool up
    assert s.nodes is not None and s.nodes.shape == s.rest_nodes.shape and s.nodes.shape[1] == 3
    s.run()
    assert s.finished
    assert s.state_hash == rec.state_hash
    with pytest.raises(palpate.RunError, match="finished"):
        s.tick()


def test_a_python_hand_presses_and_lifts(small_scene):
    s = palpate.Session(small_scene, device="python")
    s.set_pose([0.004, 0.004, 0.045])
    s.step(5)
    assert s.contact == "free" and np.allclose(s.force, 0.0)
    top = None
    for k in range(60):  # down 0.5 mm a frame, 30 mm in all
        s.set_pose([0.004, 0.004, 0.045 - 0.0005 * k])
        s.step()
        if s.contact == "touch" and top is None:
            top = 0.045 - 0.0005 * k
    assert top is not None
    assert s.force[2] > 0.5 and abs(s.force[0]) < 0.1 * s.force[2]
    assert s.proxy[2] > s.tool[2]  # the proxy stays on the surface above the tool
    log = s.samples()
    assert len(log["tick"]) > 0 and log["contact"].max() == 1.0
    s.set_pose([0.004, 0.004, 0.05])
    s.step(30)
    assert s.contact == "free"
    with pytest.raises(palpate.RunError, match="set_pose"):
        palpate.Session(small_scene).set_pose([0, 0, 0])


def test_bench_feel_returns_the_scenes_figures(small_scene):
    feel = palpate.bench.feel(small_scene)
    assert feel["ticks"] == 600 and feel["contact_ticks"] > 100
    assert feel["scene"] == "cube_press"


def test_ctrl_c_stops_a_run_whole_and_raises_keyboard_interrupt(tmp_path):
    out = tmp_path / "long"
    code = (
        "import palpate, sys\n"
        f"s = palpate.Scene({scene_path('bunny_pull.json')!r}, {{'duration_s': 60}})\n"
        "print('started', flush=True)\n"
        "try:\n"
        f"    palpate.record(s, out={str(out)!r}, frames=True)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True); sys.exit(3)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, cwd=ROOT,
                         env=dict(os.environ))
    assert p.stdout.readline().strip() == "started"
    deadline = time.monotonic() + 120
    while not (out / "frames").is_dir() or not any((out / "frames").glob("frame_*.png")):
        assert time.monotonic() < deadline and p.poll() is None
        time.sleep(0.1)
    p.send_signal(signal.SIGINT)
    rest, _ = p.communicate(timeout=120)
    assert p.returncode == 3 and "interrupted" in rest
    summary = json.loads((out / "summary.json").read_text())
    assert summary["interrupted"]
    rows = (out / "haptic.csv").read_text().splitlines()
    assert len(rows) > 1 and rows[-1].count(",") == rows[0].count(",")
