"""palpate.Scene: the command line's checks and messages, overrides from Python, warnings for old keys."""

import json
import os
import warnings

import pytest

import palpate
from conftest import palpate_cli, scene_path


def test_a_scene_file_reads_as_the_command_line_reads_it():
    s = palpate.Scene(scene_path("bunny_touch.json"))
    assert s.name == "bunny_touch"
    assert s.mode == "touch"
    assert s.duration_s > 0
    assert s.data["interaction"]["mode"] == "touch"


def test_overrides_reach_the_checked_scene(small_scene):
    s = palpate.Scene(small_scene, {"interaction.mode": "pull", "trajectory.1.pos_m": [0.004, 0.004, 0.02]})
    assert s.mode == "pull"
    assert s.data["trajectory"][1]["pos_m"] == [0.004, 0.004, 0.02]
    t = s.with_overrides(material__young_modulus_Pa=5e5)
    assert t.data["material"]["young_modulus_Pa"] == 5e5
    assert s.data["material"]["young_modulus_Pa"] == 2e5  # the first scene is untouched


def test_a_refused_scene_raises_the_command_lines_message(tmp_path, small_scene):
    small_scene["lattice"]["level"] = 9
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(small_scene))
    cli = palpate_cli("record", str(bad), "--out", str(tmp_path / "out"), check=False)
    assert cli.returncode == 1
    with pytest.raises(palpate.SceneError) as e:
        palpate.Scene(str(bad))
    assert isinstance(e.value, ValueError)
    assert cli.stderr.strip() == f"palpate: {e.value}"
    assert "lattice.level" in str(e.value)


def test_an_override_out_of_range_names_its_key(small_scene):
    with pytest.raises(palpate.SceneError, match="material.young_modulus_Pa"):
        palpate.Scene(small_scene, {"material.young_modulus_Pa": -1.0})
    with pytest.raises(palpate.SceneError, match="device.max_force_N"):
        palpate.Scene(small_scene, {"device.max_force_N": float("nan")})
    with pytest.raises(palpate.SceneError, match="'trajectory.9'"):
        palpate.Scene(small_scene, {"trajectory.9.t_s": 1.0})


def test_a_key_in_its_old_place_warns_and_still_counts(small_scene):
    small_scene["interaction"]["static_friction"] = 0.4
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        palpate.Scene(small_scene)
    assert any("material.static_friction" in str(x.message) for x in w)


def test_a_missing_file_names_it(tmp_path):
    with pytest.raises(palpate.SceneError, match="nothing.json"):
        palpate.Scene(os.fspath(tmp_path / "nothing.json"))
