"""The Python API: a matcher object in OpenCV's manner over every matcher, its input checks and
range policy, a params file as one object, __all__ per package, and docs/api.md current."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from host.api import (
    MATCHERS,
    InputError,
    MatcherParams,
    StereoMatcher,
    load_params_file,
)
from host.params_file import save_params
from host.stereo.matcher import compute_disparity
from host.stereo.synthetic import synthetic_scene
from host.tuning.disparity_range import RangePolicy, apply_range

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def scene():
    return synthetic_scene(seed=4, width=160, height=120, max_disp=20, noise=1.0)


@pytest.mark.parametrize("matcher", MATCHERS)
def test_every_matcher_computes_through_the_object(scene, matcher: str) -> None:
    m = StereoMatcher.create(matcher, block_size=5, num_disparities=32)
    disp = m.compute(scene.left, scene.right)
    assert disp.shape == scene.left.shape[:2] and disp.dtype == np.float32
    good = np.abs(disp - scene.gt) <= 1
    assert good[np.isfinite(scene.gt)].mean() > 0.5, matcher


def test_without_a_range_the_policy_gives_each_pair_its_own(scene) -> None:
    m = StereoMatcher.create("ncc", block_size=7, border="clip")
    rng = RangePolicy("coarse").resolve(scene.left, scene.right)
    assert m.disparity_range(scene.left, scene.right) == rng
    want = compute_disparity(scene.left, scene.right,
                             apply_range(MatcherParams("ncc", 7, border="clip"), rng))
    np.testing.assert_array_equal(m.compute(scene.left, scene.right), want)


@pytest.mark.parametrize("change, words", [
    (lambda a, b: (a.astype(np.int64), b), "left: dtype int64 is not supported"),
    (lambda a, b: (a, b.astype(np.uint16)), "right: dtype uint16 is not supported"),
    (lambda a, b: (a.tolist(), b), "left: expected a numpy array"),
    (lambda a, b: (a, b[:, :-2]), "left and right differ in size"),
    (lambda a, b: (np.dstack([a, a, a, a]), b), "neither grey"),
    (lambda a, b: (np.dstack([a, a, a]), b), "left is BGR and right is grey"),
])
def test_bad_images_raise_one_clear_input_error(scene, change, words: str) -> None:
    left, right = change(scene.left, scene.right)
    with pytest.raises(InputError, match=words):
        StereoMatcher.create(num_disparities=16).compute(left, right)
    assert issubclass(InputError, ValueError)


@pytest.mark.parametrize("kwargs, words", [
    ({"matcher": "nope"}, "unknown matcher 'nope'"),
    ({"block_size": 8}, "block size must be odd"),
    ({"window": 7}, "unknown matcher parameter"),
    ({"num_disparities": 16, "range_policy": "coarse"}, "not both"),
])
def test_bad_parameters_raise_at_create(kwargs: dict, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        StereoMatcher.create(**kwargs)


def test_a_params_file_loads_as_one_object_with_its_range_policy(tmp_path: Path, scene) -> None:
    path = tmp_path / "tuned.toml"
    save_params(path, MatcherParams("ncc", 7, border="clip"), {"method": "tpe"},
                disparity_range=RangePolicy("coarse", 2.0).to_table())
    f = load_params_file(path)
    assert (f.params.matcher, f.range_policy, f.tuning["method"]) == (
        "ncc", RangePolicy("coarse", 2.0), "tpe")
    m = StereoMatcher.load(path)
    assert m.disparity_range(scene.left, scene.right) == RangePolicy("coarse", 2.0).resolve(
        scene.left, scene.right)


PACKAGES = ["host.api", "host.camera", "host.commands", "host.emulator", "host.link",
            "host.servo", "host.sim", "host.stereo", "host.tuning", "host.tuning.backends",
            "host.view"]


@pytest.mark.parametrize("name", PACKAGES)
def test_each_package_says_what_it_exports(name: str) -> None:
    mod = importlib.import_module(name)
    assert mod.__all__ == sorted(mod.__all__, key=lambda s: (not s.isupper(), s))
    for n in mod.__all__:
        assert hasattr(mod, n) or importlib.import_module(f"{name}.{n}")


def test_the_api_page_is_generated_from_the_current_docstrings() -> None:
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "apidoc.py"), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
