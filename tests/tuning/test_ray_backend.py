"""host tune --ray gives the same result as a local run for the same seed, on a Ray head started
inside a network namespace that has only loopback (so nothing leaves this machine)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from host.stereo.synthetic import synthetic_scene
from tests.netns import loopback_only

pytest.importorskip("ray", reason="Ray is not installed (pip install 'stereo-servo[ray]')")


def test_ray_backend_matches_the_local_run(tmp_path: Path) -> None:
    prefix = loopback_only()
    for i, d in enumerate((16,)):
        s = synthetic_scene(seed=i, width=120, height=90, max_disp=d, noise=2.0)
        scene = tmp_path / f"s{i}"
        scene.mkdir()
        cv2.imwrite(str(scene / "left.png"), s.left)
        cv2.imwrite(str(scene / "right.png"), s.right)
        cv2.imwrite(str(scene / "disp_left.png"), np.nan_to_num(s.gt * 4).astype(np.uint16))
        (scene / "meta.json").write_text(json.dumps({"scene": scene.name, "scale": 4}))
    argv = [sys.executable, "-m", "host", "tune", str(tmp_path), "--method", "qlearning",
            "--iterations", "8", "--episodes", "2", "--seed", "3", "--block-sizes", "5:11",
            "--border", "clip", "--json"]
    env = os.environ | {"RAY_USAGE_STATS_ENABLED": "0"}
    local = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=300)
    assert local.returncode == 0, local.stderr
    on_ray = subprocess.run(
        prefix + ["ip link set lo up && exec \"$@\"", "sh", *argv, "--ray"],
        capture_output=True, text=True, env=env, timeout=300)
    assert on_ray.returncode == 0, on_ray.stderr[-2000:]
    a, b = json.loads(local.stdout), json.loads(on_ray.stdout)
    assert a["history"] == b["history"] and a["best_params"] == b["best_params"]
    assert a["evaluations"] == b["evaluations"] > 1


def test_a_bad_ray_address_is_a_one_line_error() -> None:
    r = subprocess.run([sys.executable, "-m", "host", "tune", "--ray", "not an address"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--ray ADDRESS" in r.stderr and r.stderr.count("\n") == 1



class _FakeRay:
    """Records ray.init's arguments; its init replaces SIGTERM's handler, as Ray's does."""

    def __init__(self) -> None:
        self.kw: dict = {}

    def is_initialized(self) -> bool:
        return False

    def init(self, address=None, **kw) -> None:
        self.kw = {"address": address, **kw}
        signal.signal(signal.SIGTERM, lambda *_: sys.exit(15))

    def cluster_resources(self) -> dict:
        return {"CPU": 2}

    def put(self, x):
        return x

    def remote(self, f):
        return f

    def shutdown(self) -> None:
        pass


def test_a_local_cluster_binds_loopback_and_keeps_the_commands_signal_handlers(
        monkeypatch) -> None:
    from host.tuning.backends import ray_cluster

    fake = _FakeRay()
    monkeypatch.setattr(ray_cluster, "_ray", lambda: fake)
    mine = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        ray_cluster.RayBackend(lambda p: [0.0], None)
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # not Ray's exit(15)
    finally:
        signal.signal(signal.SIGTERM, mine)
    assert fake.kw["address"] is None and fake.kw["_node_ip_address"] == "127.0.0.1"
    assert fake.kw["include_dashboard"] is False
