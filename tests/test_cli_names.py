"""The command's names: --version, the stereo-servo entry point, and a stray host.py in the
working folder named in one line instead of silently run or half-imported."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import host
from host.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_version_names_the_package_and_its_version(capsys) -> None:
    try:
        main(["--version"])
    except SystemExit as e:
        assert e.code == 0
    assert capsys.readouterr().out == f"stereo-servo {host.__version__}\n"


def _entry(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "stereo_servo", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=120)


def test_a_stray_host_py_is_named_not_run(tmp_path: Path) -> None:
    (tmp_path / "host.py").write_text("print('the stray file ran')\n")
    r = _entry(tmp_path, "--version")
    assert r.returncode == 2 and "ran" not in r.stdout
    assert r.stderr.count("\n") == 1
    assert f"{tmp_path / 'host.py'} shadows the stereo-servo package" in r.stderr


def test_the_entry_point_runs_the_cli_when_nothing_shadows_it(tmp_path: Path) -> None:
    r = _entry(tmp_path, "--version")
    assert (r.returncode, r.stdout) == (0, f"stereo-servo {host.__version__}\n"), r.stderr


def test_ctrl_c_while_the_libraries_load_is_one_line_and_130(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "stereo_servo", "eval"], cwd=tmp_path,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.3)  # numpy, OpenCV and numba take seconds to load: this lands among them
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130 and "Traceback" not in err, err
    assert err.count("\n") == 1 and "interrupted" in err
