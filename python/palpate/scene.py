"""palpate.Scene: a scene from a file or a dict, with keys overridden from Python, checked by the command line's code."""

import copy
import json
import math
import os
import warnings

from . import _palpate


def _set(data, dotted, value):
    """Sets data[a][b][c] = value for the key "a.b.c" (a number indexes a list: "trajectory.1.pos_m")."""
    parts = dotted.split(".")
    node = data
    for i, part in enumerate(parts[:-1]):
        key = int(part) if isinstance(node, list) else part
        if isinstance(node, dict) and key not in node:
            node[key] = {}
        try:
            node = node[key]
        except (IndexError, KeyError, TypeError) as e:
            raise _palpate.SceneError(f"override '{dotted}': no '{'.'.join(parts[:i + 1])}' in the scene") from e
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise _palpate.SceneError(f"override '{dotted}': '{'.'.join(parts[:-1])}' is not an object")


def _non_finite(node, at=""):
    """The dotted key of the first number JSON cannot hold (NaN, infinity) in node, or None."""
    if isinstance(node, float) and not math.isfinite(node):
        return at
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for k, v in items:
        found = _non_finite(v, f"{at}.{k}" if at else str(k))
        if found is not None:
            return found
    return None


class Scene:
    """A scene: its JSON as a dict (``data``), where it came from (``path``) and the checked scene (``native``).

    ``Scene("scenes/bunny_touch.json")``, ``Scene({...})`` or ``Scene(other)``; ``overrides`` maps dotted keys to
    values (``{"material.young_modulus_Pa": 3e5}``). A scene the command line would refuse raises
    ``palpate.SceneError`` with the command line's message; keys read from an old place give a warning.
    A relative ``mesh.file`` is relative to the scene file's folder (a dict's: the working folder).
    """

    def __init__(self, source, overrides=None, *, path=None):
        if isinstance(source, Scene):
            data, path = copy.deepcopy(source.data), path or source.path
        elif isinstance(source, (str, os.PathLike)):
            path = os.fspath(source)
            text = _palpate.read_scene_text(path)
            _palpate.parse_scene(text, path)  # the strict parse first: a key twice, a NaN, nesting
            data = json.loads(text)
        elif isinstance(source, dict):
            data, path = copy.deepcopy(source), path or "<dict>"
        else:
            raise TypeError(f"Scene(source): a path, a dict or a Scene, not {type(source).__name__}")
        for key, value in (overrides or {}).items():
            _set(data, key, value)
        bad = _non_finite(data)
        if bad is not None:
            raise _palpate.SceneError(f"scene '{path}': {bad}: not a finite number (a scene holds none)")
        self.data = data
        self.path = path
        self.native = _palpate.parse_scene(json.dumps(data, allow_nan=False), path)
        for w in self.native.warnings:
            warnings.warn(f"scene '{path}': {w}", UserWarning, stacklevel=2)

    def with_overrides(self, overrides=None, **keys):
        """A new scene with these keys changed; ``keys`` spell dots as double underscores
        (``material__young_modulus_Pa=3e5``)."""
        merged = dict(overrides or {})
        merged.update({k.replace("__", "."): v for k, v in keys.items()})
        return Scene(self, merged)

    @property
    def name(self):
        return self.native.name

    @property
    def mode(self):
        """The interaction: touch, pull or cut."""
        return self.native.mode

    @property
    def duration_s(self):
        return self.native.duration_s

    def to_json(self):
        return json.dumps(self.data, indent=2)

    def __repr__(self):
        return f"Scene({self.name!r}, mode={self.mode!r}, from {self.path!r})"
